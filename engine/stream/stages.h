#pragma once
// The stages of the stream pipeline, specialised at compile time on the features a scene
// uses. Read run_chunk(), trace_generation() and trace_slice() top to bottom: they are the
// whole algorithm for one chunk of a tile.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh/mesh_trace.h"
#include "mesh/terminator.h"
#include "parallel/parallelism.h"
#include "render/render_stats.h"
#include "render/sampling.h"
#include "render/texture.h"
#include "shapes/shapes.h"
#include "stream/profile.h"
#include "kernels/ray_stream.h"
#include "stream/shade_mode.h"
#include "stream/stream_scene.h"

namespace streamrt {

/// Hit rays regrouped by object (a stable counting sort), so that every SIMD packet of the
/// shade kernel shares one object: its transforms and material are broadcast, not gathered.
struct SortedHits {
    AlignedVec<float> ox, oy, oz, dx, dy, dz, t, wr, wg, wb, cone, lr, lg, lb, bu, bv;
    AlignedVec<std::int32_t> pixel, prim, object;  ///< object: gathered runs only
    AlignedVec<std::uint32_t> key;  ///< area lights only: light-sampling keys (reserve_keys)
    std::vector<std::uint32_t> run_start;  ///< per object, then one past the end
    void reserve(std::size_t n) {
        // Kernels read a whole packet past the last ray of a run.
        const std::size_t cap = simd::round_up_lanes(n) + simd::kMaxLanes;
        if (ox.size() < cap) {
            for (auto* a : {&ox, &oy, &oz, &dx, &dy, &dz, &t, &wr, &wg, &wb, &cone, &lr, &lg, &lb, &bu, &bv}) a->resize(cap);
            pixel.resize(cap);
            prim.resize(cap);
            object.resize(cap);
        }
    }
    void reserve_keys() {
        if (key.size() < ox.size()) key.resize(ox.size());
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
    std::vector<std::uint32_t> slot;
};

/// Scenes with more objects than this shade without sorting: the counting sort walks every
/// object's bucket per chunk and the runs get too short for whole packets. Measured
/// (docs/performance.md, "Design choices"): sorted SIMD shading is 3.2x faster at 1e3 spheres,
/// 2x at 4e3, even at 1e4, 8x slower at 1e5.
inline constexpr std::size_t kSortedShadeMaxObjects = 8192;
/// Above it, hits are regrouped by (material, shape kind) instead, whose count stays small
/// when objects share materials, and each lane gathers its own object's record; scenes with
/// meshes, or with more than this many (material, kind) pairs, shade one ray at a time.
inline constexpr std::size_t kGatheredShadeMaxKeys = 65536;

/// The shade mode a scene gets: `asked` resolved against what the scene allows.
inline ShadeMode resolve_shade_mode(const StreamScene& sc, ShadeMode asked) {
    const bool gather_ok = !sc.has_meshes && sc.materials.size() * kShapeKindCount <= kGatheredShadeMaxKeys;
    switch (asked) {
        case ShadeMode::Scalar: return ShadeMode::Scalar;
        case ShadeMode::Sorted: return ShadeMode::Sorted;
        case ShadeMode::Gathered: return gather_ok ? ShadeMode::Gathered : ShadeMode::Sorted;
        case ShadeMode::Auto: break;
    }
    if (sc.object_count <= kSortedShadeMaxObjects) return ShadeMode::Sorted;
    return gather_ok ? ShadeMode::Gathered : ShadeMode::Scalar;
}

namespace stage_detail {

inline void add(float* accum, std::int32_t pixel, const ColorT<float>& c) {
    accum[pixel * 3 + 0] += c.x;
    accum[pixel * 3 + 1] += c.y;
    accum[pixel * 3 + 2] += c.z;
}
inline std::uint64_t lanes_for(std::size_t n, int width) {
    return (std::uint64_t(n) + std::uint64_t(width) - 1) / std::uint64_t(width) * std::uint64_t(width);
}

/// Copies rays [from, from + n) of `src` into `dst` (which then holds exactly them).
inline void copy_rays(const RayStream& src, std::size_t from, std::size_t n, RayStream& dst, bool keys) {
    dst.reserve(n);
    if (keys) {  // area lights
        dst.reserve_keys();
        std::copy_n(src.key.begin() + std::ptrdiff_t(from), n, dst.key.begin());
    }
    for (auto a : {&RayStream::ox, &RayStream::oy, &RayStream::oz, &RayStream::dx, &RayStream::dy, &RayStream::dz,
                   &RayStream::t_max, &RayStream::wr, &RayStream::wg, &RayStream::wb, &RayStream::cone})
        std::copy_n((src.*a).begin() + std::ptrdiff_t(from), n, (dst.*a).begin());
    std::copy_n(src.pixel.begin() + std::ptrdiff_t(from), n, dst.pixel.begin());
    std::copy_n(src.kind.begin() + std::ptrdiff_t(from), n, dst.kind.begin());
    dst.count = n;
}

/// Cuts a generation of more than `cap` rays into slices of at most `cap` rays that each
/// hold all the rays of their pixels (pixels in order, as many whole pixels as fit), and
/// regroups `gen` so each slice is contiguous, keeping the rays' order within a slice. A
/// pixel with more than `cap` rays alone is cut, in stream order, into slices of its own.
/// Returns the slices' bounds in `gen` (first 0, last gen.count). `scratch` ends holding the
/// generation's former buffer. `keys`: the rays carry light-sampling keys (area lights).
inline std::vector<std::size_t> cut_into_slices(RayStream& gen, RayStream& scratch, std::size_t cap,
                                                std::size_t tile_pixels, std::vector<std::uint32_t>& pixel_rays,
                                                std::vector<std::uint32_t>& pixel_slice, bool keys) {
    pixel_rays.assign(tile_pixels, 0);
    for (std::size_t i = 0; i < gen.count; ++i) ++pixel_rays[std::size_t(gen.pixel[i])];
    // Each pixel's first slice: pixels are packed greedily, in pixel order.
    pixel_slice.assign(tile_pixels, 0);
    std::vector<std::size_t> size;  // rays per slice
    std::size_t fill = cap;         // rays in the last slice (cap: full, open a new one)
    for (std::size_t p = 0; p < tile_pixels; ++p) {
        const std::size_t n = pixel_rays[p];
        if (n == 0) continue;
        if (n > cap) {
            pixel_slice[p] = std::uint32_t(size.size());
            for (std::size_t left = n; left > 0; left -= std::min(left, cap)) size.push_back(std::min(left, cap));
            fill = cap;
            continue;
        }
        if (fill + n > cap) size.push_back(0), fill = 0;
        pixel_slice[p] = std::uint32_t(size.size() - 1);
        size.back() += n;
        fill += n;
    }
    std::vector<std::size_t> bounds(size.size() + 1, 0);
    for (std::size_t k = 0; k < size.size(); ++k) bounds[k + 1] = bounds[k] + size[k];
    // A stable counting sort by slice; a cut pixel's k-th ray goes to its slice k / cap.
    std::vector<std::size_t> at(bounds.begin(), bounds.end() - 1);
    pixel_rays.assign(tile_pixels, 0);  // now: the pixel's rays placed so far
    scratch.reserve(gen.count);
    if (keys) scratch.reserve_keys();
    for (std::size_t i = 0; i < gen.count; ++i) {
        const std::size_t p = std::size_t(gen.pixel[i]);
        const std::size_t j = at[pixel_slice[p] + pixel_rays[p]++ / cap]++;
        if (keys) scratch.key[j] = gen.key[i];
        scratch.ox[j] = gen.ox[i], scratch.oy[j] = gen.oy[i], scratch.oz[j] = gen.oz[i];
        scratch.dx[j] = gen.dx[i], scratch.dy[j] = gen.dy[i], scratch.dz[j] = gen.dz[i];
        scratch.t_max[j] = gen.t_max[i];
        scratch.wr[j] = gen.wr[i], scratch.wg[j] = gen.wg[i], scratch.wb[j] = gen.wb[i];
        scratch.cone[j] = gen.cone[i];
        scratch.pixel[j] = gen.pixel[i];
        scratch.kind[j] = gen.kind[i];
    }
    scratch.count = gen.count;
    std::swap(gen, scratch);
    return bounds;
}

}  // namespace stage_detail

template <bool kLighting, bool kShadows, bool kReflect, bool kRefract, bool kJitter>
struct PipelineStages {
    static constexpr bool kSecondary = kReflect || kRefract;

    /// generate: camera rays for pixels [first, first + n_pixels) of the tile, spp per pixel,
    /// consecutive, so a pixel's samples share a packet. Weight 1/spp each.
    static void generate(const StreamScene& sc, const KernelTable& kt, const Tile& tile, int first, int n_pixels,
                         Workspace& ws) {
        RayStream& rays = ws.current;
        GenerateScratch& g = ws.generate;
        const int spp = sc.settings.spp;
        const std::size_t n = std::size_t(n_pixels) * std::size_t(spp);
        rays.reserve(n);
        const bool lens = sc.features.lens;  // one scene-wide choice: the thin-lens kernel
        g.reserve(n, lens);
        // Integer bookkeeping (pixel of each ray, sample index, lattice cell) in scalar code;
        // the hashing, jitter and camera directions in the SIMD kernel.
        const int cols = grid_columns(spp);
        std::size_t i = 0;
        for (int p = first; p < first + n_pixels; ++p) {
            const int x = tile.x0 + p % tile.width(), y = tile.y0 + p / tile.width();
            const std::uint32_t pixel = std::uint32_t(std::uint64_t(y) * std::uint64_t(sc.settings.width) + std::uint64_t(x));
            int cx = 0, cy = 0;
            for (int k = 0; k < spp; ++k, ++i) {
                g.px[i] = float(x);
                g.py[i] = float(y);
                if constexpr (kJitter) {
                    g.key_pixel[i] = pixel;
                    g.key_sample[i] = std::uint32_t(k);
                    g.cell_x[i] = float(cx);
                    g.cell_y[i] = float(cy);
                    if (++cx == cols) cx = 0, ++cy;
                }
                rays.pixel[i] = p;
                rays.kind[i] = std::uint8_t(RayKind::Primary);
            }
        }
        rays.count = i;
        if (lens) {  // a second pass, so a pinhole camera runs exactly the loop above
            std::size_t j = 0;
            for (int p = first; p < first + n_pixels; ++p) {
                const int x = tile.x0 + p % tile.width(), y = tile.y0 + p / tile.width();
                const std::uint32_t pixel =
                    std::uint32_t(std::uint64_t(y) * std::uint64_t(sc.settings.width) + std::uint64_t(x));
                const LensCells cells(spp, pixel);  // render/sampling.h
                for (int k = 0; k < spp; ++k, ++j) {
                    g.key_pixel[j] = pixel;  // also at spp = 1: the lens hashes need them
                    g.key_sample[j] = std::uint32_t(k);
                    int lx, ly;
                    cells.cell(k, lx, ly);
                    g.lens_x[j] = float(lx);
                    g.lens_y[j] = float(ly);
                }
            }
        }
        GenerateJob job{n,
                        g.px.data(),
                        g.py.data(),
                        g.cell_x.data(),
                        g.cell_y.data(),
                        g.key_pixel.data(),
                        g.key_sample.data(),
                        int(sc.settings.pattern),
                        kJitter,
                        float(cols),
                        float(spp / cols),
                        &sc.camera,
                        1.f / float(spp),
                        {rays.ox.data(), rays.oy.data(), rays.oz.data(), rays.dx.data(), rays.dy.data(),
                         rays.dz.data(), rays.t_max.data(), rays.wr.data(), rays.wg.data(), rays.wb.data(),
                         rays.cone.data(), rays.pixel.data(), rays.kind.data(), &rays.count},
                        g.lens_x.data(),
                        g.lens_y.data()};
        (lens ? kt.generate_lens : kt.generate)(job);
        if (sc.features.area_lights) area_light_keys(sc, tile, first, n_pixels, rays);
    }

    /// Area lights: each camera ray's light-sampling key (render/sampling.h light_key), from
    /// its global pixel and sample index (the rays of a pixel are its samples in order).
    static void area_light_keys(const StreamScene& sc, const Tile& tile, int first, int n_pixels, RayStream& rays) {
        rays.reserve_keys();
        const int spp = sc.settings.spp;
        std::size_t i = 0;
        for (int p = first; p < first + n_pixels; ++p) {
            const int x = tile.x0 + p % tile.width(), y = tile.y0 + p / tile.width();
            const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(sc.settings.width) + std::uint64_t(x);
            for (int k = 0; k < spp; ++k, ++i) rays.key[i] = light_key(pixel, k);
        }
    }

    /// intersect: closest hit of every ray, one SIMD kernel per shape kind present.
    static void intersect(const StreamScene& sc, const KernelTable& kt, RayStream& rays,
                          AlignedVec<std::int32_t>& object, MeshHits& mesh_hits, StageFigures* fig) {
        rays.pad_tail();
        if (object.size() < rays.capacity()) object.resize(rays.capacity());
        std::fill_n(object.begin(), rays.count, -1);
        RayView view = view_of(rays);
        if (sc.has_meshes) {  // mesh kernels report the triangle and barycentrics here
            mesh_hits.reserve(rays.capacity());
            view.prim = mesh_hits.prim.data();
            view.bu = mesh_hits.u.data();
            view.bv = mesh_hits.v.data();
        }
        if (sc.accel) {  // the object hierarchy (stream/stream_accel.h)
            sc.accel->closest(kt, view, object.data(), rays.count > 0 && rays.kind[0] == std::uint8_t(RayKind::Primary));
            if (fig) fig->lanes_used += rays.count, fig->lanes_total += rays.count;
            return;
        }
        for (int k = 0; k < kShapeKindCount; ++k) {
            const auto& group = sc.groups[k];
            if (group.empty()) continue;
            if (sc.group_bounded[k])
                kt.closest_culled[k](view, object.data(), group.data(), sc.group_bounds[k].data(), group.size());
            else
                kt.closest[k](view, object.data(), group.data(), group.size());
            if (fig) {
                fig->lanes_used += rays.count;
                fig->lanes_total += stage_detail::lanes_for(rays.count, shape_computes_in_double(ShapeKind(k)) ? kt.float_lanes / 2 : kt.float_lanes);
            }
        }
    }

    /// The shading rules for rays of generation `depth`. The stream's weights carry the
    /// sample's 1/spp, so the cut-off (defined on the refl / trans product alone, as in the
    /// recursive engine) is scaled by it.
    static ShadeRules<float> shade_rules(const StreamScene& sc, int depth) {
        const RenderSettings& s = sc.settings;
        return {s.degree, float(s.ambient), kSecondary && depth < s.depth, float(s.cutoff / s.spp), sc.camera.spread};
    }

    /// Where shade_hit's results go on the scalar path: the local colour into the tile,
    /// shadow and child rays appended to their streams.
    struct ScalarSink {
        static constexpr bool kTestsShadowsNow = false;
        float* accum;
        std::int32_t px;
        RayStream& next;
        ShadowStream& shadows;
        RayCounts& counts;
        const std::uint32_t* keys;  ///< area lights only (else unread): the rays' keys
        std::size_t i;              ///< the ray shaded

        std::uint32_t light_key() const { return keys[i]; }

        void local(const ColorT<float>& c) { stage_detail::add(accum, px, c); }
        void shadow(bool send, const Vec3f& from, const Vec3f& to, float t_max, const ColorT<float>& c) {
            if (!send) return;
            const std::size_t j = shadows.count++;
            shadows.ox[j] = from.x;
            shadows.oy[j] = from.y;
            shadows.oz[j] = from.z;
            shadows.dx[j] = to.x;
            shadows.dy[j] = to.y;
            shadows.dz[j] = to.z;
            shadows.t_max[j] = t_max;
            shadows.cr[j] = c.x;
            shadows.cg[j] = c.y;
            shadows.cb[j] = c.z;
            shadows.pixel[j] = px;
        }
        void child(bool send, const Vec3f& from, const Vec3f& dir, const ColorT<float>& weight, const ColorT<float>&,
                   float cone, RayKind kind) {
            if (!send) return;
            if (keys) next.key[next.count] = keys[i];  // area lights: the child inherits the key
            push(next, next.count++, from, dir, weight, cone, px, kind);
            ++(kind == RayKind::Reflected ? counts.reflected : counts.refracted);
        }
    };

    /// shade + spawn, one ray at a time (shade_hit in render/shading.h with V = float):
    /// local terms into the tile, shadow rays when degree 5 asks for visibility, reflected
    /// and refracted rays appended to `next` (only surviving rays move on). Misses bring the
    /// background.
    static void shade(const StreamScene& sc, const RayStream& rays, const AlignedVec<std::int32_t>& object,
                      const MeshHits& mesh_hits, int depth, RayStream& next, ShadowStream& shadows, float* accum,
                      RayCounts& counts) {
        using namespace stage_detail;
        const ShadeRules<float> rules = shade_rules(sc, depth);
        // This path serves scenes with many objects, where each hit's records are likely
        // cache misses: fetch them a few rays ahead (in leaf order, neighbouring rays mostly
        // hit objects close in memory).
        constexpr std::size_t kPrefetchDistance = 8;
        const std::uint32_t* keys = sc.features.area_lights ? rays.key.data() : nullptr;
        for (std::size_t i = 0; i < rays.count; ++i) {
            if (i + kPrefetchDistance < rays.count && object[i + kPrefetchDistance] >= 0) {
                const std::size_t ahead = std::size_t(object[i + kPrefetchDistance]);
                __builtin_prefetch(&sc.objects[ahead]);
                __builtin_prefetch(reinterpret_cast<const char*>(&sc.objects[ahead]) + 64);
                __builtin_prefetch(&sc.surfaces[ahead]);
            }
            const ColorT<float> w{rays.wr[i], rays.wg[i], rays.wb[i]};
            const std::int32_t px = rays.pixel[i];
            const std::int32_t id = object[i];
            if (id < 0) {
                add(accum, px, mul(w, sc.background));
                continue;
            }
            const KernelObject& ob = sc.objects[std::size_t(id)];
            const SurfaceRecord& sf = sc.surfaces[std::size_t(id)];
            const MaterialT<float>& m = sc.materials[sf.material];
            const ShapeKind kind = ShapeKind(ob.kind);
            const Vec3f o{rays.ox[i], rays.oy[i], rays.oz[i]}, d{rays.dx[i], rays.dy[i], rays.dz[i]};
            const float t = rays.t_max[i];
            // The canonical hit point (the kernels keep only t and the object) gives the
            // normal, brought back with Mn; the world point is the ray's own.
            const Vec3f pc = apply_point(ob.xf.m, o) + apply_vector(ob.xf.m, d) * t;
            const Vec3f p = o + d * t;
            const Vec3f nc =
                kind == ShapeKind::Mesh
                    ? mesh_normal<float>(*ob.xf.mesh, std::uint32_t(mesh_hits.prim[i]), mesh_hits.u[i], mesh_hits.v[i],
                                         ob.xf.param != 0.f)
                    : visit_shape(kind, [&](auto shape) { return shape.template normal<float>(pc, ob.xf.param); });
            const ArrivingRay<float> arriving{o, d, t, rays.cone[i], w, w};
            ScalarSink sink{accum, px, next, shadows, counts, keys, i};
            const Vec3f n_out = apply_normal(ob.xf.m, nc);
            ColorT<float> color{sf.color[0], sf.color[1], sf.color[2]};
            if (m.texture) {  // the texture replaces the object's colour (render/texture.h)
                const float footprint = footprint_width(rays.cone[i], rules.spread, t, dot(d, n_out));
                const float scale = canonical_per_world<float>(ob.xf.m);
                color = kind == ShapeKind::Mesh
                            ? mesh_texture_color(m, *ob.xf.mesh, std::uint32_t(mesh_hits.prim[i]), mesh_hits.u[i],
                                                 mesh_hits.v[i], scale, footprint)
                            : texture_color(m, kind, pc, ob.xf.param, scale, footprint);
            }
            // A smooth mesh's shadow rays start from its curved patch, not the flat triangle.
            const bool smooth = kind == ShapeKind::Mesh && ob.xf.param != 0.f;
            const auto shadow_point = [&](const Vec3f& at) {
                if (!smooth) return at;
                return at + terminator_shift(ob.xf.m, smooth_corners<float>(*ob.xf.mesh, std::uint32_t(mesh_hits.prim[i])),
                                             mesh_hits.u[i], mesh_hits.v[i], meets_outside(n_out, d));
            };
            shade_hit<kLighting, kShadows, kReflect, kRefract>(rules, m, sc.lights.data(), sc.lights.size(), arriving,
                                                               p, n_out, color, true, sink, shadow_point);
        }
    }

    /// shade + spawn, SIMD: misses bring the background; hits are regrouped by object and
    /// each run goes through the shade kernel; local colours then go into the tile in the
    /// sorted order (fixed for a given tile, so the picture does not depend on threads).
    static void shade_sorted(const StreamScene& sc, const KernelTable& kt, const RayStream& rays,
                             const AlignedVec<std::int32_t>& object, int depth, Workspace& ws, float* accum,
                             RayCounts& counts, bool gathered) {
        using namespace stage_detail;
        SortedHits& h = ws.sorted;
        // The run key of a hit: its object, or (gathered) its material and shape kind.
        const auto key_of = [&](std::int32_t id) -> std::size_t {
            if (!gathered) return std::size_t(id);
            return std::size_t(sc.surfaces[std::size_t(id)].material) * kShapeKindCount + sc.objects[id].kind;
        };
        const std::size_t n_keys = gathered ? sc.materials.size() * kShapeKindCount : sc.object_count;
        h.run_start.assign(n_keys + 1, 0);
        std::size_t hits = 0;
        for (std::size_t i = 0; i < rays.count; ++i) {
            const std::int32_t id = object[i];
            if (id < 0) {
                add(accum, rays.pixel[i], mul(ColorT<float>{rays.wr[i], rays.wg[i], rays.wb[i]}, sc.background));
                continue;
            }
            ++h.run_start[key_of(id) + 1];
            ++hits;
        }
        for (std::size_t k = 1; k <= n_keys; ++k) h.run_start[k] += h.run_start[k - 1];
        h.reserve(hits);
        if (sc.features.area_lights) h.reserve_keys();
        {
            std::vector<std::uint32_t>& next_slot = ws.slot;
            next_slot.assign(h.run_start.begin(), h.run_start.end() - 1);
            for (std::size_t i = 0; i < rays.count; ++i) {
                const std::int32_t id = object[i];
                if (id < 0) continue;
                const std::size_t j = next_slot[key_of(id)]++;
                h.ox[j] = rays.ox[i];
                h.oy[j] = rays.oy[i];
                h.oz[j] = rays.oz[i];
                h.dx[j] = rays.dx[i];
                h.dy[j] = rays.dy[i];
                h.dz[j] = rays.dz[i];
                h.t[j] = rays.t_max[i];
                h.wr[j] = rays.wr[i];
                h.wg[j] = rays.wg[i];
                h.wb[j] = rays.wb[i];
                h.cone[j] = rays.cone[i];
                h.pixel[j] = rays.pixel[i];
                if (gathered) h.object[j] = id;
                if (sc.features.area_lights) h.key[j] = rays.key[i];
                if (sc.has_meshes) {
                    h.prim[j] = ws.mesh_hits.prim[i];
                    h.bu[j] = ws.mesh_hits.u[i];
                    h.bv[j] = ws.mesh_hits.v[i];
                }
            }
            // A gathered packet reads a whole batch of ids past the last hit: valid ones.
            if (gathered) std::fill_n(h.object.begin() + std::ptrdiff_t(hits), simd::kMaxLanes, 0);
        }
        const std::size_t next_before = ws.next.count;
        RayStream& nx = ws.next;
        ShadowStream& sh = ws.shadows;
        ShadeJob job{h.ox.data(), h.oy.data(), h.oz.data(), h.dx.data(), h.dy.data(), h.dz.data(), h.t.data(),
                     h.wr.data(), h.wg.data(), h.wb.data(), h.cone.data(), h.pixel.data(), 0, 0, nullptr, {}, nullptr,
                     sc.lights.data(), sc.lights.size(), shade_rules(sc, depth), h.lr.data(), h.lg.data(), h.lb.data(),
                     {nx.ox.data(), nx.oy.data(), nx.oz.data(), nx.dx.data(), nx.dy.data(), nx.dz.data(),
                      nx.t_max.data(), nx.wr.data(), nx.wg.data(), nx.wb.data(), nx.cone.data(), nx.pixel.data(),
                      nx.kind.data(), &nx.count},
                     {sh.ox.data(), sh.oy.data(), sh.oz.data(), sh.dx.data(), sh.dy.data(), sh.dz.data(),
                      sh.t_max.data(), sh.cr.data(), sh.cg.data(), sh.cb.data(), sh.pixel.data(), &sh.count}};
        job.prim = h.prim.data();
        job.bu = h.bu.data();
        job.bv = h.bv.data();
        if (sc.features.area_lights) job.key = h.key.data(), job.next.key = nx.key.data();
        const int variant = (kLighting ? 1 : 0) | (kShadows ? 2 : 0) | (kReflect ? 4 : 0) | (kRefract ? 8 : 0);
        const ShadeFn fn = gathered ? kt.shade_gathered[variant] : kt.shade[variant];
        if (gathered) {
            job.ids = h.object.data();
            job.objects = sc.objects;
            job.surfaces = sc.surfaces.data();
        }
        for (std::size_t k = 0; k < n_keys; ++k) {
            if (h.run_start[k] == h.run_start[k + 1]) continue;
            job.begin = h.run_start[k];
            job.end = h.run_start[k + 1];
            if (gathered) {
                job.material = &sc.materials[k / kShapeKindCount];
                job.kind = ShapeKind(k % kShapeKindCount);
            } else {
                const SurfaceRecord& sf = sc.surfaces[k];
                job.object = &sc.objects[k];
                job.color = {sf.color[0], sf.color[1], sf.color[2]};
                job.material = &sc.materials[sf.material];
            }
            fn(job);
        }
        for (std::size_t j = 0; j < hits; ++j) add(accum, h.pixel[j], {h.lr[j], h.lg[j], h.lb[j]});
        if constexpr (kSecondary) {
            for (std::size_t j = next_before; j < nx.count; ++j) {
                if (nx.kind[j] == std::uint8_t(RayKind::Reflected)) ++counts.reflected;
                else ++counts.refracted;
            }
        }
    }

    /// Gathered shading emits shadow rays run by run, (material, kind) after (material, kind):
    /// rays of one packet then start from far apart in the tile, and at 1e6 objects the
    /// hierarchy walk of such packets cost 1.6x that of rays in pixel order (measured,
    /// docs/performance.md). A counting sort over the tile's pixels puts them back in pixel
    /// order (stable: a pixel's rays keep their light order).
    static void order_shadows_by_pixel(Workspace& ws, std::size_t tile_pixels) {
        ShadowStream& in = ws.shadows;
        ShadowStream& out = ws.shadows_in_pixel_order;
        const std::size_t n = in.count;
        std::vector<std::uint32_t>& start = ws.slot;
        start.assign(tile_pixels + 1, 0);
        for (std::size_t i = 0; i < n; ++i) ++start[std::size_t(in.pixel[i]) + 1];
        for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
        out.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t j = start[std::size_t(in.pixel[i])]++;
            out.ox[j] = in.ox[i], out.oy[j] = in.oy[i], out.oz[j] = in.oz[i];
            out.dx[j] = in.dx[i], out.dy[j] = in.dy[i], out.dz[j] = in.dz[i];
            out.t_max[j] = in.t_max[i];
            out.cr[j] = in.cr[i], out.cg[j] = in.cg[i], out.cb[j] = in.cb[i];
            out.pixel[j] = in.pixel[i];
        }
        out.count = n;
        std::swap(in, out);
    }

    static void push(RayStream& r, std::size_t j, const Vec3f& o, const Vec3f& d, const ColorT<float>& w,
                     float cone, std::int32_t px, RayKind kind) {
        r.cone[j] = cone;
        r.ox[j] = o.x;
        r.oy[j] = o.y;
        r.oz[j] = o.z;
        r.dx[j] = d.x;
        r.dy[j] = d.y;
        r.dz[j] = d.z;
        r.t_max[j] = std::numeric_limits<float>::infinity();
        r.wr[j] = w.x;
        r.wg[j] = w.y;
        r.wb[j] = w.z;
        r.pixel[j] = px;
        r.kind[j] = std::uint8_t(kind);
    }

    /// occlusion: any-hit kernels per shape kind (early exit per packet), then the light of
    /// every unblocked shadow ray goes into its pixel.
    static void occlusion(const StreamScene& sc, const KernelTable& kt, ShadowStream& shadows, float* accum,
                          StageFigures* fig) {
        shadows.pad_tail();
        if (sc.accel) {  // the object hierarchy (stream/stream_accel.h)
            sc.accel->any(kt, view_of(shadows));
            if (fig) fig->lanes_used += shadows.count, fig->lanes_total += shadows.count;
        }
        for (int k = 0; !sc.accel && k < kShapeKindCount; ++k) {
            const auto& group = sc.groups[k];
            if (group.empty()) continue;
            if (sc.group_bounded[k])
                kt.any_culled[k](view_of(shadows), group.data(), sc.group_bounds[k].data(), group.size());
            else
                kt.any[k](view_of(shadows), group.data(), group.size());
            if (fig) {
                fig->lanes_used += shadows.count;
                fig->lanes_total += stage_detail::lanes_for(shadows.count, shape_computes_in_double(ShapeKind(k)) ? kt.float_lanes / 2 : kt.float_lanes);
            }
        }
        for (std::size_t i = 0; i < shadows.count; ++i)
            if (shadows.t_max[i] > 0.f) stage_detail::add(accum, shadows.pixel[i], {shadows.cr[i], shadows.cg[i], shadows.cb[i]});
    }

    /// What the stages of one chunk share.
    struct Chunk {
        const StreamScene& sc;
        const KernelTable& kt;
        const Tile& tile;
        Workspace& ws;
        float* accum;
        RayCounts& counts;
        StreamProfile* profile;
        ShadeMode shade_mode;
        std::size_t slice_rays;  ///< the most rays traced at once
        StageFigures* fig(Stage s) const { return profile ? &profile->stages[int(s)] : nullptr; }
    };

    /// One slice of generation `depth`: intersect, shade, occlusion; the rays it spawns (at
    /// most two per ray) go to `spawned`.
    static void trace_slice(const Chunk& c, int depth, RayStream& rays, RayStream& spawned) {
        const StreamScene& sc = c.sc;
        Workspace& ws = c.ws;
        std::swap(ws.next, spawned);  // the shade stage appends to ws.next
        {
            StageTimer timer(c.fig(Stage::Intersect));
            intersect(sc, c.kt, rays, ws.object, ws.mesh_hits, c.fig(Stage::Intersect));
            if (c.profile) c.fig(Stage::Intersect)->rays_in += rays.count, c.fig(Stage::Intersect)->rays_out += rays.count;
        }
        {
            StageTimer timer(c.fig(Stage::Shade));
            // Room for every ray spawning both children and a shadow ray per light.
            ws.next.reserve(kSecondary ? rays.count * 2 : 0);
            if (sc.features.area_lights) ws.next.reserve_keys();
            // Area lights send `samples` shadow rays each (StreamScene::shadow_rays_per_hit).
            if constexpr (kShadows) ws.shadows.reserve(rays.count * sc.shadow_rays_per_hit);
            if (c.shade_mode == ShadeMode::Scalar)
                shade(sc, rays, ws.object, ws.mesh_hits, depth, ws.next, ws.shadows, c.accum, c.counts);
            else
                shade_sorted(sc, c.kt, rays, ws.object, depth, ws, c.accum, c.counts, c.shade_mode == ShadeMode::Gathered);
            if (kShadows && c.shade_mode == ShadeMode::Gathered)
                order_shadows_by_pixel(ws, std::size_t(c.tile.width() * c.tile.height()));
            if (c.profile) {
                c.fig(Stage::Shade)->rays_in += rays.count;
                c.fig(Stage::Shade)->rays_out += ws.next.count + (kShadows ? ws.shadows.count : 0);
            }
        }
        if constexpr (kShadows) {
            StageTimer timer(c.fig(Stage::Occlusion));
            c.counts.shadow += ws.shadows.count;
            occlusion(sc, c.kt, ws.shadows, c.accum, c.fig(Stage::Occlusion));
            if (c.profile) {
                c.fig(Stage::Occlusion)->rays_in += ws.shadows.count;
                for (std::size_t i = 0; i < ws.shadows.count; ++i) c.fig(Stage::Occlusion)->rays_out += ws.shadows.t_max[i] > 0.f;
            }
        }
        std::swap(ws.next, spawned);
        rays.count = 0;  // traced
    }

    /// Traces generation `depth` and everything it spawns, deepest first: a generation of
    /// more than slice_rays rays is cut into slices, and each slice's descendants are traced
    /// before the next slice. A slice spawns at most twice its rays, so the rays held are at
    /// most 2 x slice_rays for each generation on the way down, whatever the depth, instead
    /// of 2^depth; a generation traced whole gives its buffer back before its children are
    /// traced, so chains of such generations reuse the same few buffers.
    /// The slices hold whole pixels (cut_into_slices) and pixels do not interact, so each
    /// pixel gets the same terms as when every generation is traced whole; one ray at a time
    /// (scalar shading) in the same order, bit for bit. Only a pixel with more than
    /// slice_rays rays in one generation is cut itself. Either way, the order is fixed by the
    /// tile's content: the same picture for every -j.
    static void trace_generation(const Chunk& c, int depth, RayStream&& rays) {
        Workspace& ws = c.ws;
        RayStream gen = std::move(rays);
        if (gen.count <= c.slice_rays) {  // whole: no copy
            RayStream spawned = ws.take();
            trace_slice(c, depth, gen, spawned);
            ws.give(std::move(gen));
            descend(c, depth, std::move(spawned));
            return;
        }
        const std::vector<std::size_t> bounds =
            stage_detail::cut_into_slices(gen, ws.regroup, c.slice_rays, std::size_t(c.tile.width() * c.tile.height()),
                                          ws.pixel_rays, ws.pixel_slice, c.sc.features.area_lights);
        for (std::size_t k = 0; k + 1 < bounds.size(); ++k) {
            RayStream slice = ws.take(), spawned = ws.take();
            stage_detail::copy_rays(gen, bounds[k], bounds[k + 1] - bounds[k], slice, c.sc.features.area_lights);
            trace_slice(c, depth, slice, spawned);
            ws.give(std::move(slice));
            descend(c, depth, std::move(spawned));
        }
        gen.count = 0;
        ws.give(std::move(gen));
    }

    /// The rays generation `depth` spawned: traced, or (none) their buffer given back.
    static void descend(const Chunk& c, int depth, RayStream&& spawned) {
        if (kSecondary && spawned.count > 0) trace_generation(c, depth + 1, std::move(spawned));
        else c.ws.give(std::move(spawned));
    }

    /// The whole algorithm for one chunk of a tile: camera rays, then every generation they
    /// spawn (trace_generation). slice_rays: the most rays traced at once.
    static void run_chunk(const StreamScene& sc, const KernelTable& kt, const Tile& tile, int first, int n_pixels,
                          Workspace& ws, float* accum, RayCounts& counts, StreamProfile* profile,
                          ShadeMode shade_mode, std::size_t slice_rays) {
        const Chunk c{sc, kt, tile, ws, accum, counts, profile, shade_mode, std::max<std::size_t>(1, slice_rays)};
        {
            StageTimer timer(c.fig(Stage::Generate));
            generate(sc, kt, tile, first, n_pixels, ws);
            counts.primary += ws.current.count;
            if (profile) c.fig(Stage::Generate)->rays_out += ws.current.count, c.fig(Stage::Generate)->rays_in += std::uint64_t(n_pixels);
        }
        RayStream primary = ws.take();
        std::swap(primary, ws.current);
        trace_generation(c, 0, std::move(primary));
    }
};

}  // namespace streamrt
