#pragma once
// Structure-of-arrays ray packets. Arrays are padded to a multiple of kMaxLanes (16 floats,
// AVX-512) and 64-byte aligned in every build, so a full-width load of the last packet stays
// inside the arrays; padding lanes are inert (t_max < 0 can never accept a hit) and
// the kernels never write them back into results that matter.
#include <cstddef>
#include <cstdint>

#include "render/render_stats.h"
#include "simd/lanes.h"

namespace streamrt {

using simd::AlignedVec;

/// Makes the lanes between count and the next multiple of kMaxLanes inert (t_max < 0, a
/// finite ray), so full-width kernels can run over the last packet.
template <class Stream>
inline void make_tail_inert(Stream& s) {
    const std::size_t end = simd::round_up_lanes(s.count);
    for (std::size_t i = s.count; i < end; ++i) {
        s.ox[i] = s.oy[i] = s.oz[i] = 0.f;
        s.dx[i] = s.dy[i] = 0.f;
        s.dz[i] = 1.f;
        s.t_max[i] = -1.f;
    }
}

/// Rays of one generation of one tile chunk.
struct RayStream {
    std::size_t count = 0;
    AlignedVec<float> ox, oy, oz, dx, dy, dz;
    AlignedVec<float> t_max;  ///< hits accepted for t in (0, t_max)
    AlignedVec<float> wr, wg, wb;  ///< throughput weight: what the ray's colour is worth in its pixel
    AlignedVec<float> cone;        ///< footprint width at the origin (ray cone, texture filtering)
    AlignedVec<std::int32_t> pixel;  ///< tile-local pixel the result accumulates into
    AlignedVec<std::uint8_t> kind;   ///< RayKind, for the profile
    /// Scenes with area lights only (empty otherwise): the camera sample's light-sampling key
    /// (render/sampling.h light_key), inherited by every ray the sample spawns.
    AlignedVec<std::uint32_t> key;

    /// Makes room for n rays (padded, plus a packet of slack for the kernels' compacting
    /// stores) and sets count = 0; keeps capacity.
    void reserve(std::size_t n) {
        const std::size_t cap = simd::round_up_lanes(n) + simd::kMaxLanes;
        if (ox.size() < cap) {
            for (auto* a : {&ox, &oy, &oz, &dx, &dy, &dz, &t_max, &wr, &wg, &wb, &cone}) a->resize(cap);
            pixel.resize(cap);
            kind.resize(cap);
        }
        count = 0;
    }
    std::size_t capacity() const { return ox.size(); }
    /// Gives `key` the stream's capacity (scenes with area lights, after reserve).
    void reserve_keys() {
        if (key.size() < ox.size()) key.resize(ox.size());
    }
    /// Makes the lanes between count and the next multiple of kMaxLanes inert.
    void pad_tail() { make_tail_inert(*this); }
    /// Calls f(&RayStream::array) for every per-ray array but `key` (which only scenes with
    /// area lights fill): the one list of them that copying code walks.
    template <class F>
    static void for_each_array(F&& f) {
        for (auto a : {&RayStream::ox, &RayStream::oy, &RayStream::oz, &RayStream::dx, &RayStream::dy, &RayStream::dz,
                       &RayStream::t_max, &RayStream::wr, &RayStream::wg, &RayStream::wb, &RayStream::cone})
            f(a);
        f(&RayStream::pixel);
        f(&RayStream::kind);
    }
};

/// Shadow rays: a segment towards a light and the colour it brings if nothing blocks it.
struct ShadowStream {
    std::size_t count = 0;
    AlignedVec<float> ox, oy, oz, dx, dy, dz, t_max;
    AlignedVec<float> cr, cg, cb;  ///< contribution (already weighted) if unoccluded
    AlignedVec<std::int32_t> pixel;
    void reserve(std::size_t n) {
        const std::size_t cap = simd::round_up_lanes(n) + simd::kMaxLanes;  // slack as in RayStream
        if (ox.size() < cap) {
            for (auto* a : {&ox, &oy, &oz, &dx, &dy, &dz, &t_max, &cr, &cg, &cb}) a->resize(cap);
            pixel.resize(cap);
        }
        count = 0;
    }
    std::size_t capacity() const { return ox.size(); }
    void pad_tail() { make_tail_inert(*this); }
};

/// Rays as the kernels see them: pointers into a RayStream or a ShadowStream.
struct RayView {
    std::size_t count;
    const float *ox, *oy, *oz, *dx, *dy, *dz;
    float* t_max;  ///< closest-hit kernels shrink it to the best t; any-hit kernels set 0 on occlusion
    // Mesh hits (closest hit only; nullptr when not wanted): triangle number and barycentric
    // coordinates (weights of its second and third vertices), meaningful for rays whose
    // closest object is a mesh.
    std::int32_t* prim = nullptr;
    float* bu = nullptr;
    float* bv = nullptr;
    /// Closest-hit mesh walks of packets that have scattered hand a stack entry that at most
    /// this many live lanes reached to the single-ray walk (kernels/mesh_kernel.h,
    /// scattered_packet_lanes; 0: packet walk only). The stream engine sets it per generation
    /// (stream/stages.h); shadow rays keep the packet walk (measured: the hybrid lost there).
    std::uint32_t single_ray_lanes = 0;
};

inline RayView view_of(RayStream& r) {
    return {r.count, r.ox.data(), r.oy.data(), r.oz.data(), r.dx.data(), r.dy.data(), r.dz.data(), r.t_max.data()};
}
inline RayView view_of(ShadowStream& r) {
    return {r.count, r.ox.data(), r.oy.data(), r.oz.data(), r.dx.data(), r.dy.data(), r.dz.data(), r.t_max.data()};
}

}  // namespace streamrt
