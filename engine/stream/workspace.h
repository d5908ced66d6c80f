#pragma once
// The stream engine's per-thread buffers, reused from chunk to chunk: camera-ray inputs,
// generations of rays, hits regrouped for shading, shadow rays.
#include <cstdint>
#include <utility>
#include <vector>

#include "kernels/ray_stream.h"
#include "simd/lanes.h"

namespace streamrt {

/// Hit rays regrouped by object (a stable counting sort), so that every SIMD packet of the
/// shade kernel shares one object: its transforms and material are broadcast, not gathered.
struct SortedHits {
    AlignedVec<float> lr, lg, lb;        ///< each hit's local colour, in run order
    AlignedVec<std::int32_t> order;      ///< run order -> the hit's index in the slice (ShadeJob::order)
    std::vector<std::uint32_t> run_start;  ///< per run key, then one past the end
    std::vector<std::uint32_t> fill;       ///< per run key, the next place while ordering
    std::size_t hits = 0;                  ///< the hits of the slice shaded last
    void reserve(std::size_t n) {
        // Kernels read a whole packet past the last ray of a run.
        const std::size_t cap = simd::round_up_lanes(n) + simd::kMaxLanes;
        if (order.size() < cap) {
            for (auto* a : {&lr, &lg, &lb}) a->resize(cap);
            order.resize(cap);
        }
    }
};

/// Per ray, the triangle a mesh hit landed on and its barycentrics (read for mesh objects only).
struct MeshHits {
    AlignedVec<std::int32_t> prim;
    AlignedVec<float> u, v;
    void reserve(std::size_t cap) {
        if (prim.size() < cap) {
            prim.resize(cap);
            u.resize(cap);
            v.resize(cap);
        }
    }
};

/// Per-ray inputs of the generate kernel.
struct GenerateScratch {
    AlignedVec<float> px, py, cell_x, cell_y;
    AlignedVec<std::uint32_t> key_pixel, key_sample;
    AlignedVec<float> lens_x, lens_y;  ///< thin lens only: the lens lattice cells (else empty)
    void reserve(std::size_t n, bool lens) {
        const std::size_t cap = simd::round_up_lanes(n);
        if (px.size() < cap) {
            for (auto* a : {&px, &py, &cell_x, &cell_y}) a->assign(cap, 0.f);
            key_pixel.assign(cap, 0);
            key_sample.assign(cap, 0);
        }
        if (lens && lens_x.size() < cap) {
            lens_x.assign(cap, 0.f);
            lens_y.assign(cap, 0.f);
        }
    }
};

/// Per-thread buffers, reused from chunk to chunk.
struct Workspace {
    GenerateScratch generate;
    RayStream current;  ///< camera rays
    RayStream next;     ///< the rays a slice spawns (swapped in and out around the shade stage)
    /// Buffers of generations no longer in use (PipelineStages::trace_generation takes and
    /// gives back), so a thread holds as many as were ever in use at once.
    std::vector<RayStream> spare;
    RayStream regroup;  ///< a generation regrouped into slices (cut_into_slices)
    RayStream take() {
        if (spare.empty()) return RayStream{};
        RayStream r = std::move(spare.back());
        spare.pop_back();
        r.count = 0;
        return r;
    }
    void give(RayStream&& r) { spare.push_back(std::move(r)); }
    std::vector<std::uint32_t> pixel_rays, pixel_slice;  ///< per tile pixel (cut_into_slices)
    AlignedVec<std::int32_t> object;  ///< closest-hit object per ray of the slice traced
    MeshHits mesh_hits;               ///< triangle and barycentrics per ray of the slice (mesh hits)
    ShadowStream shadows, shadows_in_pixel_order;
    SortedHits sorted;
    /// Scratch of the shade stage, one use at a time: each ray's run key (shade_sorted), then
    /// each pixel's first shadow ray (order_shadows_by_pixel).
    std::vector<std::uint32_t> slot;
};

}  // namespace streamrt
