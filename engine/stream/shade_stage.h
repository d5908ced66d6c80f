#pragma once
// The shade stage of the stream pipeline: hits become local colour, shadow rays and child
// rays, one ray at a time (scalar, shade_hit in render/shading.h) or regrouped into runs that
// share an object, or a material and shape kind, for the SIMD shade kernels.
#include <cstdint>
#include <limits>
#include <vector>

#include "kernels/kernel_table.h"
#include "kernels/shade_job.h"
#include "mesh/mesh_trace.h"
#include "mesh/terminator.h"
#include "render/render_stats.h"
#include "render/texture.h"
#include "shapes/shapes.h"
#include "stream/shade_mode.h"
#include "stream/stream_scene.h"
#include "stream/workspace.h"

namespace streamrt {

/// Scenes with more objects than this shade without sorting: the counting sort walks every
/// object's bucket per chunk and the runs get too short for whole packets. Measured
/// (docs/performance.md, "Design choices"): sorted SIMD shading is 3.2x faster at 1e3 spheres,
/// 2x at 4e3, even at 1e4, 8x slower at 1e5.
inline constexpr std::size_t kSortedShadeMaxObjects = 8192;
/// Above it, hits are regrouped by (material, shape kind) instead, whose count stays small
/// when objects share materials, and each lane gathers its own object's record (a mesh hit
/// also its object's mesh and smooth flag: instances of one mesh share a run); scenes with
/// more than this many (material, kind) pairs shade one ray at a time. Measured
/// (docs/performance.md, "### Instances"): 10,000 instances of one mesh shade in 0.065 CPU s
/// gathered against 0.137 one ray at a time (0.034 for 100 instances, runs by object).
inline constexpr std::size_t kGatheredShadeMaxKeys = 65536;

/// The shade mode a scene gets: `asked` resolved against what the scene allows. A scene with
/// CSG objects is not gathered: a run of one material and kind may mix a shape's two records
/// (ObjectXf::flip), and the gathered kernel reads no per-lane flip.
inline ShadeMode resolve_shade_mode(const StreamScene& sc, ShadeMode asked) {
    const bool gather_ok = sc.materials.size() * kShapeKindCount <= kGatheredShadeMaxKeys && !sc.csg;
    switch (asked) {
        case ShadeMode::Scalar: return ShadeMode::Scalar;
        case ShadeMode::Sorted: return ShadeMode::Sorted;
        case ShadeMode::Gathered: return gather_ok ? ShadeMode::Gathered : ShadeMode::Sorted;
        case ShadeMode::Auto: break;
    }
    if (sc.object_count <= kSortedShadeMaxObjects) return ShadeMode::Sorted;
    return gather_ok ? ShadeMode::Gathered : ShadeMode::Scalar;
}

/// The unit world normal shown where object `xf`'s canonical normal is nc: Mn nc, turned
/// round on a CSG shape's surface seen from the shape's outside (ObjectXf::flip), so that it
/// points out of the CSG result.
inline Vec3f shown_normal(const ObjectXf& xf, const Vec3f& nc) { return apply_normal(xf.m, xf.flip ? -nc : nc); }

namespace stage_detail {

inline ColorT<float> load_sum(const float* accum, std::int32_t pixel) {
    return {accum[pixel * 3 + 0], accum[pixel * 3 + 1], accum[pixel * 3 + 2]};
}
inline void store_sum(float* accum, std::int32_t pixel, const ColorT<float>& c) {
    accum[pixel * 3 + 0] = c.x;
    accum[pixel * 3 + 1] = c.y;
    accum[pixel * 3 + 2] = c.z;
}
inline void add(float* accum, std::int32_t pixel, const ColorT<float>& c) {
    accum[pixel * 3 + 0] += c.x;
    accum[pixel * 3 + 1] += c.y;
    accum[pixel * 3 + 2] += c.z;
}
/// accum[pixel[order[j]]] += (r, g, b)[j] for j in [0, n), in that order: a run of rays of
/// one pixel adds in registers and stores once. The same additions in the same order as one
/// add() per ray, so the same bits; without the store-to-load wait of each ray on the one before.
inline void add_runs(float* __restrict accum, const std::int32_t* __restrict pixel, const std::int32_t* __restrict order,
                     const float* __restrict r, const float* __restrict g, const float* __restrict b, std::size_t n) {
    for (std::size_t j = 0; j < n;) {
        const std::int32_t p = pixel[order[j]];
        float* a = accum + std::ptrdiff_t(p) * 3;
        float sr = a[0], sg = a[1], sb = a[2];
        do {
            sr += r[j], sg += g[j], sb += b[j];
        } while (++j < n && pixel[order[j]] == p);
        a[0] = sr, a[1] = sg, a[2] = sb;
    }
}
/// Shadow rays as the shade stage sends them (ShadeJob::shadows, ScalarSink): each unblocked
/// one's colour (t_max > 0) added to its hit's local colour, `pixel` holding the hit's place
/// in SortedHits::order; in stream order, where a hit's shadow rays come in light order.
inline void add_unblocked_to_hits(float* __restrict lr, float* __restrict lg, float* __restrict lb,
                                  const ShadowStream& s) {
    const float *__restrict t = s.t_max.data(), *__restrict r = s.cr.data(), *__restrict g = s.cg.data(),
                *__restrict b = s.cb.data();
    const std::int32_t* __restrict hit = s.pixel.data();
    for (std::size_t i = 0; i < s.count; ++i) {
        if (!(t[i] > 0.f)) continue;
        const std::size_t h = std::size_t(hit[i]);
        lr[h] += r[i], lg[h] += g[i], lb[h] += b[i];
    }
}
inline std::uint64_t lanes_for(std::size_t n, int width) {
    return (std::uint64_t(n) + std::uint64_t(width) - 1) / std::uint64_t(width) * std::uint64_t(width);
}

}  // namespace stage_detail

/// The shade stage for a scene's features (the same flags as PipelineStages).
template <bool kLighting, bool kShadows, bool kReflect, bool kRefract, bool kBounce>
struct ShadeStage {
    static constexpr bool kSecondary = kReflect || kRefract || kBounce;
    /// The most children one ray spawns: a reflected, a refracted and (degree 6) a diffuse one.
    static constexpr std::size_t kChildrenPerRay = kBounce ? 3 : 2;

    /// The shading rules for rays of generation `depth`. The cut-off is defined on the refl /
    /// trans product alone, as in the recursive engine, and the stream's weights also carry
    /// the sample's weight, 1 / `samples_per_slot` (SampleRequest), so it is scaled by that.
    /// (Scaled by the settings' 1/spp, adaptive samples, whose spp is their cap, were cut at a
    /// 64th of the cut-off: docs/adaptive-sampling.md.)
    static ShadeRules<float> shade_rules(const StreamScene& sc, int depth, int samples_per_slot) {
        const RenderSettings& s = sc.settings;
        return {.degree = s.degree,
                .ambient = float(s.ambient),
                .spawn = kSecondary && depth < s.depth,
                .cutoff = s.degree >= 6 ? 0.f : float(s.cutoff / samples_per_slot),  // degree 6: roulette instead
                .spread = sc.camera.spread,
                .eye = {0.f, 0.f, 0.f},  // the engine's origin is the eye (stream_scene.cpp)
                .roulette = depth >= kRouletteFromDepth,
                .sequence_bits = first_bounce_bits(s, depth),
                .throughput_scale = float(samples_per_slot)};
    }

    /// Where shade_hit's results go on the scalar path: the local colour into the tile (with
    /// shadow rays, into the hit's place k of `hits`, to wait for its unblocked light as on
    /// the SIMD path: add_shadowed_locals), shadow and child rays appended to their streams.
    struct ScalarSink {
        static constexpr bool kTestsShadowsNow = false;
        float* accum;
        std::int32_t px;
        RayStream& next;
        ShadowStream& shadows;
        RayCounts& counts;
        const std::uint32_t* keys;  ///< area lights only (else unread): the rays' keys
        std::size_t i;              ///< the ray shaded
        SortedHits& hits;
        std::size_t k;              ///< its place among the slice's hits (SortedHits::order)
        bool rekey;                 ///< degree 6: children take keys of their own (child_key)

        std::uint32_t light_key() const { return keys[i]; }

        void local(const ColorT<float>& c) {
            if constexpr (kShadows) hits.lr[k] = c.x, hits.lg[k] = c.y, hits.lb[k] = c.z;
            else stage_detail::add(accum, px, c);
        }
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
            shadows.pixel[j] = std::int32_t(k);  // the hit's place, not the pixel
        }
        void child(bool send, const Vec3f& from, const Vec3f& dir, const ColorT<float>& weight, const ColorT<float>&,
                   float cone, RayKind kind) {
            if (!send) return;
            // Area lights: the child inherits the key; degree 6: it takes its own.
            if (keys) next.key[next.count] = rekey ? child_key(keys[i], std::uint32_t(kind)) : keys[i];
            push(next, next.count++, from, dir, weight, cone, px, kind);
            ++counts.children(kind);
        }
    };

    /// shade + spawn, one ray at a time (shade_hit in render/shading.h with V = float):
    /// local terms into the tile, shadow rays when degree 5 asks for visibility, reflected
    /// and refracted rays appended to `next` (only surviving rays move on). Misses bring the
    /// background.
    static void shade(const StreamScene& sc, const RayStream& rays, const AlignedVec<std::int32_t>& object,
                      const MeshHits& mesh_hits, int depth, int samples_per_slot, RayStream& next,
                      ShadowStream& shadows, SortedHits& hits, float* accum, RayCounts& counts) {
        using namespace stage_detail;
        const ShadeRules<float> rules = shade_rules(sc, depth, samples_per_slot);
        if constexpr (kShadows) hits.reserve(rays.count);
        hits.hits = 0;
        // This path serves scenes with many objects, where each hit's records are likely
        // cache misses: fetch them a few rays ahead (in leaf order, neighbouring rays mostly
        // hit objects close in memory).
        constexpr std::size_t kPrefetchDistance = 8;
        const std::uint32_t* keys = sc.features.keys ? rays.key.data() : nullptr;
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
            const ShapeKind kind = ShapeKind(ob.xf.kind);
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
            const std::size_t k = hits.hits;
            if constexpr (kShadows) hits.order[k] = std::int32_t(i), ++hits.hits;
            ScalarSink sink{accum, px, next, shadows, counts, keys, i, hits, k, rules.degree >= 6};
            const Vec3f n_out = shown_normal(ob.xf, nc);
            ColorT<float> color{sf.color[0], sf.color[1], sf.color[2]};
            if (m.texture) {  // the texture replaces the object's colour (render/texture.h)
                const float footprint = footprint_width(rays.cone[i], rules.spread, t, dot(d, n_out));
                const float scale = canonical_per_world<float>(ob.xf.m);
                color = kind == ShapeKind::Mesh
                            ? mesh_texture_color(m, *ob.xf.mesh, std::uint32_t(mesh_hits.prim[i]), mesh_hits.u[i],
                                                 mesh_hits.v[i], scale, footprint)
                            : texture_color(m, kind, pc, ob.xf.param, scale, footprint);
            } else if (m.vertex_colors && kind == ShapeKind::Mesh && ob.xf.mesh->vertex_colors) {
                color = mesh_vertex_color(*ob.xf.mesh, std::uint32_t(mesh_hits.prim[i]), mesh_hits.u[i], mesh_hits.v[i]);
            }
            // A smooth mesh's shadow rays start from its curved patch, not the flat triangle.
            const bool smooth = kind == ShapeKind::Mesh && ob.xf.param != 0.f;
            const auto shadow_point = [&](const Vec3f& at) {
                if (!smooth) return at;
                return at + terminator_shift(ob.xf.m, smooth_corners<float>(*ob.xf.mesh, std::uint32_t(mesh_hits.prim[i])),
                                             mesh_hits.u[i], mesh_hits.v[i], meets_outside(n_out, d));
            };
            shade_hit<kLighting, kShadows, kReflect, kRefract, kBounce>(rules, m, sc.lights.data(), sc.lights.size(),
                                                                        arriving, p, n_out, color, true, sink,
                                                                        shadow_point);
        }
    }

    /// shade + spawn, SIMD: misses bring the background; hits are put in runs by object (an
    /// index in run order, SortedHits::order) and each run goes through the shade kernel;
    /// local colours then go into the tile in run order (fixed for a given tile, so the
    /// picture does not depend on threads).
    static void shade_sorted(const StreamScene& sc, const KernelTable& kt, const RayStream& rays,
                             const AlignedVec<std::int32_t>& object, int depth, int samples_per_slot, Workspace& ws,
                             float* accum, RayCounts& counts, bool gathered) {
        using namespace stage_detail;
        SortedHits& h = ws.sorted;
        // The run key of a hit: its object, or (gathered) its material and shape kind.
        const auto key_of = [&](std::int32_t id) -> std::size_t {
            if (!gathered) return std::size_t(id);
            return std::size_t(sc.surfaces[std::size_t(id)].material) * kShapeKindCount + sc.objects[id].xf.kind;
        };
        const std::size_t n_keys = gathered ? sc.materials.size() * kShapeKindCount : sc.object_count;
        h.run_start.assign(n_keys + 1, 0);
        // Each ray's run key (kMissKey: a miss, which brings the background now), counted.
        // Neighbouring rays mostly share their pixel and their object, so the counts and the
        // background sums are kept in registers along a run of one key or one pixel: the
        // same additions in the same order, without each waiting on the store of the last.
        constexpr std::uint32_t kMissKey = ~0u;
        std::vector<std::uint32_t>& key = ws.slot;
        key.resize(rays.count);
        std::size_t hits = 0;
        {
            std::uint32_t* __restrict count = h.run_start.data() + 1;
            const std::int32_t* __restrict ids = object.data();
            std::uint32_t* __restrict keys = key.data();
            std::uint32_t run_key = kMissKey, run = 0;
            std::int32_t bg_pixel = -1;  // the pixel whose background sum is in bg
            ColorT<float> bg{};
            for (std::size_t i = 0; i < rays.count; ++i) {
                const std::int32_t id = ids[i];
                if (id < 0) {
                    keys[i] = kMissKey;
                    const std::int32_t p = rays.pixel[i];
                    if (p != bg_pixel) {
                        if (bg_pixel >= 0) store_sum(accum, bg_pixel, bg);
                        bg = load_sum(accum, p);
                        bg_pixel = p;
                    }
                    bg = bg + mul(ColorT<float>{rays.wr[i], rays.wg[i], rays.wb[i]}, sc.background);
                    continue;
                }
                const std::uint32_t k = std::uint32_t(key_of(id));
                keys[i] = k;
                if (k != run_key) {
                    if (run > 0) count[run_key] += run;
                    run_key = k, run = 0;
                }
                ++run;
                ++hits;
            }
            if (run > 0) count[run_key] += run;
            if (bg_pixel >= 0) store_sum(accum, bg_pixel, bg);
        }
        for (std::size_t k = 1; k <= n_keys; ++k) h.run_start[k] += h.run_start[k - 1];
        h.reserve(hits);
        // The run order: the slice index of each hit, run after run, each run in stream order
        // (a stable counting sort). The kernels read the rays through it.
        {
            h.fill.assign(h.run_start.begin(), h.run_start.end() - 1);
            std::uint32_t* __restrict fill = h.fill.data();
            const std::uint32_t* __restrict keys = key.data();
            std::int32_t* __restrict order = h.order.data();
            std::uint32_t run_key = kMissKey, at = 0;
            for (std::size_t i = 0; i < rays.count; ++i) {
                const std::uint32_t k = keys[i];
                if (k == kMissKey) continue;
                if (k != run_key) {
                    if (run_key != kMissKey) fill[run_key] = at;
                    run_key = k, at = fill[k];
                }
                order[at++] = std::int32_t(i);
            }
            // Past the last run, whole packets read a hit (gathered runs read its object's id).
            std::fill_n(order + hits, simd::kMaxLanes, hits > 0 ? order[hits - 1] : 0);
        }
        // The children's regions (ShadeJob::next, next_refracted, next_diffuse): at most one
        // ray per hit each, plus a packet of slack for the compacting stores.
        const std::size_t region = simd::round_up_lanes(hits) + simd::kMaxLanes;
        RayStream& nx = ws.next;
        ShadowStream& sh = ws.shadows;
        std::size_t refracted = 0;  // the refracted children's count (the reflected: nx.count)
        std::size_t diffuse = 0;    // the diffuse children's count
        if constexpr (kSecondary) {
            nx.reserve(kChildrenPerRay * region);
            if (sc.features.keys) nx.reserve_keys();
        }
        ShadeJob job{.ox = rays.ox.data(),
                     .oy = rays.oy.data(),
                     .oz = rays.oz.data(),
                     .dx = rays.dx.data(),
                     .dy = rays.dy.data(),
                     .dz = rays.dz.data(),
                     .t = rays.t_max.data(),
                     .wr = rays.wr.data(),
                     .wg = rays.wg.data(),
                     .wb = rays.wb.data(),
                     .cone = rays.cone.data(),
                     .pixel = rays.pixel.data(),
                     .order = h.order.data(),
                     .begin = 0,
                     .end = 0,
                     .object = nullptr,
                     .color = {},
                     .material = nullptr,
                     .lights = sc.lights.data(),
                     .n_lights = sc.lights.size(),
                     .rules = shade_rules(sc, depth, samples_per_slot),
                     .lr = h.lr.data(),
                     .lg = h.lg.data(),
                     .lb = h.lb.data(),
                     .next = append_view(nx),
                     .next_refracted = region_view(nx, region, &refracted),
                     .next_diffuse = kBounce ? region_view(nx, 2 * region, &diffuse) : RayAppend{},
                     .shadows = append_view(sh),
                     .prim = ws.mesh_hits.prim.data(),
                     .bu = ws.mesh_hits.u.data(),
                     .bv = ws.mesh_hits.v.data()};
        if (sc.features.keys) {
            job.key = rays.key.data(), job.next.key = nx.key.data(), job.next_refracted.key = nx.key.data() + region;
            if constexpr (kBounce) job.next_diffuse.key = nx.key.data() + 2 * region;
            job.rekey = job.rules.degree >= 6;
        }
        const int variant =
            (kLighting ? 1 : 0) | (kShadows ? 2 : 0) | (kReflect ? 4 : 0) | (kRefract ? 8 : 0) | (kBounce ? 16 : 0);
        const ShadeFn fn = gathered ? kt.shade_gathered[variant] : kt.shade[variant];
        if (gathered) {
            job.ids = object.data();
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
        h.hits = hits;
        // With shadow rays the local colours wait for their unblocked light (add_shadowed_locals).
        if constexpr (!kShadows) add_runs(accum, rays.pixel.data(), h.order.data(), h.lr.data(), h.lg.data(), h.lb.data(), hits);
        if constexpr (kSecondary) {
            counts.reflected += nx.count;
            counts.refracted += refracted;
            counts.diffuse += diffuse;
            join_region(nx, region, refracted, sc.features.keys);
            if constexpr (kBounce) join_region(nx, 2 * region, diffuse, sc.features.keys);
        }
    }

    /// The append view of `r`'s arrays from ray `from` on, counting into `count`.
    static RayAppend region_view(RayStream& r, std::size_t from, std::size_t* count) {
        RayAppend v = append_view(r);
        for (float** a : {&v.ox, &v.oy, &v.oz, &v.dx, &v.dy, &v.dz, &v.t_max, &v.wr, &v.wg, &v.wb, &v.cone}) *a += from;
        v.pixel += from;
        v.kind += from;
        v.count = count;
        return v;
    }
    /// Appends rays [from, from + n) of `s` to its first s.count rays (from >= s.count: a
    /// forward copy, overlap allowed).
    static void join_region(RayStream& s, std::size_t from, std::size_t n, bool keys) {
        if (n == 0) return;
        const auto move = [&](auto& a) {
            std::copy(a.begin() + std::ptrdiff_t(from), a.begin() + std::ptrdiff_t(from + n), a.begin() + std::ptrdiff_t(s.count));
        };
        RayStream::for_each_array([&](auto a) { move(s.*a); });
        if (keys) move(s.key);
        s.count += n;
    }
    /// After the occlusion stage: the unblocked shadow rays' light into their hits' local
    /// colours, then the local colours into the pixels in SortedHits::order (runs on the SIMD
    /// path, the stream on the scalar one). A pixel's sum thus takes each hit's whole local
    /// colour (ambient, then its lights in order, as the recursive engine sums a hit) as one
    /// term, whichever packets its hits shared.
    static void add_shadowed_locals(Workspace& ws, const RayStream& rays, float* accum) {
        SortedHits& h = ws.sorted;
        stage_detail::add_unblocked_to_hits(h.lr.data(), h.lg.data(), h.lb.data(), ws.shadows);
        stage_detail::add_runs(accum, rays.pixel.data(), h.order.data(), h.lr.data(), h.lg.data(), h.lb.data(), h.hits);
    }

    /// Gathered shading emits shadow rays run by run, (material, kind) after (material, kind):
    /// rays of one packet then start from far apart in the tile, and at 1e6 objects the
    /// hierarchy walk of such packets cost 1.6x that of rays in pixel order (measured,
    /// docs/performance.md). A counting sort over the tile's pixels puts them back in pixel
    /// order (stable: a pixel's rays keep their light order).
    static void order_shadows_by_pixel(Workspace& ws, const RayStream& rays, std::size_t tile_pixels) {
        ShadowStream& in = ws.shadows;
        ShadowStream& out = ws.shadows_in_pixel_order;
        const std::size_t n = in.count;
        // A shadow ray's `pixel` is its hit's run position (ShadeJob::shadows).
        const auto pixel_of = [&](std::size_t i) { return std::size_t(rays.pixel[std::size_t(ws.sorted.order[std::size_t(in.pixel[i])])]); };
        std::vector<std::uint32_t>& start = ws.slot;
        start.assign(tile_pixels + 1, 0);
        for (std::size_t i = 0; i < n; ++i) ++start[pixel_of(i) + 1];
        for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
        out.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t j = start[pixel_of(i)]++;
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
};

}  // namespace streamrt
