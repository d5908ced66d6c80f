#pragma once
// A field of random spheres and its ray sets, shared by the sphere timing programs
// (perf/bvh_bench.cpp, perf/peer/embree_rays.cpp). Not a test.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "kernels/accel_kernel_table.h"
#include "kernels/kernel_table.h"
#include "kernels/ray_stream.h"
#include "parallel/pixel_order.h"
#include "render/camera_rays.h"
#include "scene/scene.h"
#include "scene/scene_bvh.h"
#include "stream/stream_accel.h"
#include "bench_clock.h"

namespace streamrt::perf {

struct SphereRec {
    double x, y, z, r;
};

/// N spheres on a jittered grid over a square field (as scripts/random_spheres.py, without its
/// quadratic overlap search), a checkered plane, two point lights, a camera looking down at
/// the whole field. Degree 5, depth 0: primary + shadow rays.
inline Scene random_spheres(std::size_t n, std::vector<SphereRec>* out = nullptr, std::uint32_t seed = 1) {
    Scene s;
    s.settings.width = 1280;
    s.settings.height = 720;
    s.settings.spp = 1;
    s.settings.depth = 0;
    s.settings.degree = 5;
    s.settings.background = {0.5, 0.65, 0.85};
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::size_t g = std::size_t(std::ceil(std::sqrt(double(n))));
    const double cell = 4.0, side = cell * double(g);
    s.camera.look_at = true;
    s.camera.eye = {0, 0.75 * side + 2, 0.85 * side + 2};
    s.camera.look = {0, 0, -0.05 * side};
    s.camera.fov = 45;
    s.lights.push_back({LightKind::Point, {-0.4 * side, side + 4, 0.6 * side}, {0, -1, 0}, {0.8, 0.8, 0.8}, 30});
    s.lights.push_back({LightKind::Point, {0.6 * side, 0.7 * side + 3, 0.2 * side}, {0, -1, 0}, {0.45, 0.45, 0.5}, 30});
    Object plane;
    plane.kind = ShapeKind::Plane;
    Material floor;
    floor.checker = true;
    floor.checker_color = {0.25, 0.25, 0.25};
    floor.cell = cell / 2;
    s.add_object(plane, floor, {});
    Material matte;
    matte.diff = 0.85;
    matte.spec = 0.3;
    for (std::size_t i = 0; i < n; ++i) {
        const double r = cell * (0.2 + 0.25 * u(rng));
        const double x = -side / 2 + cell * (double(i % g) + 0.5) + (cell / 2 - r) * (2 * u(rng) - 1);
        const double z = -side / 2 + cell * (double(i / g) + 0.5) + (cell / 2 - r) * (2 * u(rng) - 1);
        Object o;
        o.kind = ShapeKind::Sphere;
        o.color = {0.1 + 0.9 * u(rng), 0.1 + 0.9 * u(rng), 0.1 + 0.9 * u(rng)};
        o.md = glm::dmat4x3(translate_matrix({x, r, z}) * scale_matrix({r, r, r}));
        s.add_object(o, matte, {});
        if (out) out->push_back({x, r, z, r});
    }
    return s;
}

/// The field's rays in the stream engine's order, chunks of 4096 (16 tiles of 16x16 pixels,
/// each tile's pixels in Z order, as the engine hands them where rays walk the object tree:
/// parallel/pixel_order.h): camera rays through the pixel centres; at each camera ray's hit
/// (the plane or a sphere, found by the stream's hierarchy `sa`), in the same order, a
/// mirror-reflected ray and a shadow ray to the first light.
struct SphereRays {
    std::vector<RayStream> primary, reflected;
    std::vector<ShadowStream> shadow;
};

inline SphereRays sphere_rays(const Scene& s, const std::vector<SphereRec>& sph, const StreamAccel& sa,
                              const KernelTable& kt) {
    const CameraRays<float> cam = CameraRays<float>::from(s);
    const int W = s.settings.width, H = s.settings.height;
    constexpr std::size_t kChunk = 4096;
    SphereRays out;
    std::vector<std::pair<int, int>> order;
    for (int ty = 0; ty < H; ty += kTileSize)
        for (int tx = 0; tx < W; tx += kTileSize) {
            const Tile tile{tx, ty, std::min(W, tx + kTileSize), std::min(H, ty + kTileSize)};
            std::uint32_t local[kTileSize * kTileSize];
            const int n = z_order_pixels(tile, local);
            for (int k = 0; k < n; ++k)
                order.push_back({tx + int(local[k] % std::uint32_t(tile.width())),
                                 ty + int(local[k] / std::uint32_t(tile.width()))});
        }
    for (std::size_t c = 0; c < order.size(); c += kChunk) {
        RayStream r;
        const std::size_t m = std::min(kChunk, order.size() - c);
        r.reserve(m);
        for (std::size_t k = 0; k < m; ++k) {
            const Vec3f d = cam.direction(float(order[c + k].first) + 0.5f, float(order[c + k].second) + 0.5f);
            r.ox[k] = cam.origin.x, r.oy[k] = cam.origin.y, r.oz[k] = cam.origin.z;
            r.dx[k] = d.x, r.dy[k] = d.y, r.dz[k] = d.z;
            r.t_max[k] = INFINITY;
        }
        r.count = m;
        r.pad_tail();
        out.primary.push_back(r);
    }
    const Light& L = s.lights[0];
    for (const RayStream& r0 : out.primary) {
        RayStream r = r0;
        AlignedVec<std::int32_t> obj(r.capacity(), -1);
        sa.closest(kt, view_of(r), obj.data(), true);
        RayStream rr;
        ShadowStream sh;
        rr.reserve(r.count);
        sh.reserve(r.count);
        for (std::size_t k = 0; k < r.count; ++k) {
            if (obj[k] < 0) continue;
            const Vec3f o{r.ox[k], r.oy[k], r.oz[k]}, d{r.dx[k], r.dy[k], r.dz[k]};
            const Vec3f p = o + d * r.t_max[k];
            Vec3f nrm{0, 1, 0};
            if (obj[k] > 0) {
                const SphereRec& q = sph[std::size_t(obj[k] - 1)];
                nrm = normalize(Vec3f{float(p.x - q.x), float(p.y - q.y), float(p.z - q.z)});
            }
            const Vec3f from = p + nrm * 1e-3f;
            const Vec3f refl_d = d - nrm * (2.f * dot(d, nrm));
            const std::size_t j = rr.count++;
            rr.ox[j] = from.x, rr.oy[j] = from.y, rr.oz[j] = from.z;
            rr.dx[j] = refl_d.x, rr.dy[j] = refl_d.y, rr.dz[j] = refl_d.z;
            rr.t_max[j] = INFINITY;
            const std::size_t i = sh.count++;
            const Vec3f to{float(L.pos.x - from.x), float(L.pos.y - from.y), float(L.pos.z - from.z)};
            sh.ox[i] = from.x, sh.oy[i] = from.y, sh.oz[i] = from.z;
            sh.dx[i] = to.x, sh.dy[i] = to.y, sh.dz[i] = to.z;
            sh.t_max[i] = 1.f;
        }
        rr.pad_tail();
        sh.pad_tail();
        out.reflected.push_back(rr);
        out.shadow.push_back(sh);
    }
    return out;
}

/// The hierarchy's leaf objects as the stream engine lays them out, for timing its kernels
/// alone (the plane stays outside the hierarchy).
inline std::vector<KernelObject> leaf_objects(const Scene& s, const accel::SceneBvh& sb) {
    std::vector<KernelObject> prims;
    for (std::uint32_t k = 0; k < sb.bvh.prim_index.size(); ++k)
        prims.push_back(kernel_object(s, sb.bvh.prim_index[k], std::int32_t(k), glm::dvec3(0.0)));
    return prims;
}

/// Result of timing one ray set: Mrays/s (median of the repetitions) and rays hit (closest)
/// or blocked (any hit), as a check that two tracers traced the same rays.
struct SetTiming {
    double mrays = 0;
    std::size_t hits = 0;
};

/// A hierarchy kernel over every chunk of `set` (each chunk copied fresh before its clock
/// starts), median of `reps` passes.
template <class Stream, class Trace>
SetTiming time_set(const std::vector<Stream>& set, int reps, Trace&& trace) {
    std::vector<double> secs;
    std::size_t rays = 0, hits = 0;
    for (int rep = 0; rep < reps; ++rep) {
        rays = hits = 0;
        double t = 0;
        for (const Stream& r0 : set) {
            Stream r = r0;
            const double t0 = now();
            hits += trace(r);
            t += now() - t0;
            rays += r.count;
        }
        secs.push_back(t);
    }
    std::sort(secs.begin(), secs.end());
    return {double(rays) / secs[secs.size() / 2] * 1e-6, hits};
}

inline SetTiming time_closest(const std::vector<RayStream>& set, BvhClosestFn fn, const AccelView& view, int reps) {
    return time_set(set, reps, [&](RayStream& r) {
        AlignedVec<std::int32_t> obj(r.capacity(), -1);
        fn(view, view_of(r), obj.data());
        return std::size_t(std::count_if(obj.begin(), obj.begin() + std::ptrdiff_t(r.count), [](std::int32_t o) { return o >= 0; }));
    });
}

inline SetTiming time_any(const std::vector<ShadowStream>& set, BvhAnyFn fn, const AccelView& view, int reps) {
    return time_set(set, reps, [&](ShadowStream& r) {
        fn(view, view_of(r));
        return std::size_t(std::count(r.t_max.begin(), r.t_max.begin() + std::ptrdiff_t(r.count), 0.f));
    });
}

}  // namespace streamrt::perf
