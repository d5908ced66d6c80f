#pragma once
// Ray sets over one mesh and streamrt's timing of them, shared by the mesh timing programs
// (perf/mesh_walk_bench.cpp, perf/peer/embree_rays.cpp). Not a test.
//
// A view (1280x720 by default): primary rays in 4x4 pixel tiles, traced once through the flat
// mesh kernel for their hits; at each primary hit, in the same order, a shadow ray to a point
// light (any hit), a mirror-reflected ray, a glass-refracted ray (index 1.5) and a diffuse ray
// (uniform over the hemisphere: incoherent) (closest hit). Each stream is padded to 16 lanes
// with inactive rays (t_max = 0).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh/mesh.h"
#include "simd/lanes.h"
#include "bench_clock.h"

namespace streamrt::perf {

/// A ray stream padded to 16 lanes with inactive rays (t_max = 0).
struct Stream {
    simd::AlignedVec<float> ox, oy, oz, dx, dy, dz, t_max;
    std::size_t count = 0;
    void add(const Vec3f& o, const Vec3f& d, float t) {
        ox.push_back(o.x), oy.push_back(o.y), oz.push_back(o.z);
        dx.push_back(d.x), dy.push_back(d.y), dz.push_back(d.z);
        t_max.push_back(t);
        ++count;
    }
    void pad() {
        const std::size_t n = count;
        while (ox.size() % 16) add({0, 0, 0}, {0, 0, 1}, 0.f);
        count = n;
    }
    RayView view(float* t) const { return {count, ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), t}; }
    /// The live rays in a random order (a fixed seed: the same order every run). Screen order
    /// lets each walk find its nodes in cache from the walk before; a renderer's deep rays
    /// (inside glass, after several bounces) come in no such order.
    void shuffle(std::uint32_t seed = 7) {
        std::mt19937 rng(seed);
        for (std::size_t i = count; i > 1; --i) {
            const std::size_t j = std::uniform_int_distribution<std::size_t>(0, i - 1)(rng);
            for (auto* a : {&ox, &oy, &oz, &dx, &dy, &dz, &t_max}) std::swap((*a)[i - 1], (*a)[j]);
        }
    }
};

struct Streams {
    Stream primary, shadow, mirror, glass, diffuse;
};

/// The camera and the light of the ray sets (the defaults: mesh_walk_bench's view of the unit
/// sphere).
struct View {
    Vec3f eye{0.4f, 0.8f, 3.2f};
    Vec3f look{0, 0, 0};
    float fov_deg = 45.f;  ///< vertical
    Vec3f light{3, 5, 4};
    int width = 1280, height = 720;
};

/// The view of a mesh of any size: mesh_walk_bench's direction of view and light, the eye at
/// the distance where a sphere of the box's largest half-extent, centred in it, fills the
/// picture's height (a unit sphere then covers 44 % of the 16:9 picture; View{} 27 %).
inline View view_of_bounds(const double lo[3], const double hi[3]) {
    const Vec3f c{float(0.5 * (lo[0] + hi[0])), float(0.5 * (lo[1] + hi[1])), float(0.5 * (lo[2] + hi[2]))};
    const float r = 0.5f * float(std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]}));
    View v;
    const float dist = r / std::sin(0.5f * v.fov_deg * 3.14159265f / 180.f);
    v.eye = c + dist * normalize(View{}.eye);
    v.look = c;
    v.light = c + (dist / length(View{}.eye)) * View{}.light;
    return v;
}

/// The five ray streams of the view: primary rays traced once (packet walk) for the hits.
inline Streams make_streams(const Mesh& mesh, const KernelTable& kt, const ObjectXf& xf, const View& view = {}) {
    Streams s;
    const int w = view.width, h = view.height;
    const Vec3f eye = view.eye;
    const Vec3f fwd = normalize(view.look - eye);
    const Vec3f right = normalize(cross(fwd, Vec3f{0, 1, 0})), up = cross(right, fwd);
    const float scale = std::tan(0.5f * view.fov_deg * 3.14159265f / 180.f);
    for (int ty = 0; ty < h; ty += 4)
        for (int tx = 0; tx < w; tx += 4)
            for (int y = ty; y < std::min(ty + 4, h); ++y)
                for (int x = tx; x < std::min(tx + 4, w); ++x) {
                    const float px = (2.f * (x + 0.5f) / w - 1.f) * scale * w / h, py = (1.f - 2.f * (y + 0.5f) / h) * scale;
                    s.primary.add(eye, normalize(fwd + px * right + py * up), 1e30f);
                }
    s.primary.pad();
    simd::AlignedVec<float> t(s.primary.t_max), bu(t.size()), bv(t.size());
    simd::AlignedVec<std::int32_t> id(t.size(), -1), prim(t.size(), -1);
    RayView v = s.primary.view(t.data());
    v.prim = prim.data(), v.bu = bu.data(), v.bv = bv.data();
    kt.closest[int(ShapeKind::Mesh)](v, id.data(), &xf, 1);
    const Vec3f light = view.light;
    std::mt19937 rng(3);
    std::normal_distribution<float> gauss(0.f, 1.f);
    for (std::size_t i = 0; i < s.primary.count; ++i) {
        if (id[i] != 0) continue;
        const Vec3f o{s.primary.ox[i], s.primary.oy[i], s.primary.oz[i]}, d{s.primary.dx[i], s.primary.dy[i],
                                                                                s.primary.dz[i]};
        const Vec3f p = o + t[i] * d;
        const std::array<float, 9> hit = mesh.triangle(std::size_t(prim[i]));
        const float* q = hit.data();
        Vec3f n = normalize(cross(Vec3f{q[3] - q[0], q[4] - q[1], q[5] - q[2]}, Vec3f{q[6] - q[0], q[7] - q[1], q[8] - q[2]}));
        if (dot(n, d) > 0) n = -n;
        const Vec3f out = p + 1e-4f * n, in = p - 1e-4f * n;
        const Vec3f to_light = light - out;
        const float dist = length(to_light);
        s.shadow.add(out, (1.f / dist) * to_light, dist);
        s.mirror.add(out, d - 2.f * dot(d, n) * n, 1e30f);
        const float eta = 1.f / 1.5f, c = -dot(d, n), k = 1.f - eta * eta * (1.f - c * c);
        s.glass.add(in, normalize(eta * d + (eta * c - std::sqrt(k)) * n), 1e30f);
        Vec3f r{gauss(rng), gauss(rng), gauss(rng)};  // uniform over the outer hemisphere
        if (dot(r, n) < 0) r = -r;
        s.diffuse.add(out, normalize(r), 1e30f);
    }
    s.shadow.pad();
    s.mirror.pad();
    s.glass.pad();
    s.diffuse.pad();
    return s;
}

/// The same mesh with every packet handed to the single-ray walk at the root, and the
/// transform `xf` pointed at it.
struct SingleRayMesh {
    std::shared_ptr<const Mesh> mesh;
    ObjectXf xf;
    SingleRayMesh(const Mesh& m, const ObjectXf& object) : mesh(m.with_single_ray_lanes(16)), xf(object) {
        xf.mesh = &mesh->view();
    }
};

/// One of the five ray sets, with its name and whether it is an any-hit (shadow) set.
struct RaySet {
    const char* name;
    const Stream* st;
    bool any;
};

/// The ray sets in table order; `only` ("primary,shadow" ...; empty: all) keeps those it names.
inline std::vector<RaySet> ray_sets(const Streams& s, const std::string& only) {
    std::vector<RaySet> kinds;
    for (const RaySet& k : {RaySet{"primary", &s.primary, false}, RaySet{"shadow", &s.shadow, true},
                             RaySet{"mirror", &s.mirror, false}, RaySet{"glass", &s.glass, false},
                             RaySet{"diffuse", &s.diffuse, false}})
        if (only.empty() || std::string(",").append(only).append(",").find(std::string(",").append(k.name).append(",")) !=
                                std::string::npos)
            kinds.push_back(k);
    return kinds;
}

/// Median seconds of `reps` runs of fn().
template <class Fn>
double median_seconds(int reps, Fn&& fn) {
    std::vector<double> secs;
    for (int r = 0; r < reps; ++r) secs.push_back(fn());
    std::sort(secs.begin(), secs.end());
    return secs[secs.size() / 2];
}

/// Mrays/s of the stream through the level's flat mesh kernel (KernelTable closest/any[Mesh],
/// this thread), median of reps runs. `hits`, when given, receives the number of rays that
/// hit (closest) or were blocked (any) in the last run.
inline double mrays(const Stream& st, bool any, const KernelTable& kt, const ObjectXf& xf, int reps,
                    std::size_t* hits = nullptr) {
    simd::AlignedVec<float> t(st.t_max.size()), bu(t.size()), bv(t.size());
    simd::AlignedVec<std::int32_t> id(t.size()), prim(t.size());
    const double sec = median_seconds(reps, [&] {
        std::copy(st.t_max.begin(), st.t_max.end(), t.begin());
        std::fill(id.begin(), id.end(), -1);
        RayView v = st.view(t.data());
        const double t0 = now();
        if (any) {
            kt.any[int(ShapeKind::Mesh)](v, &xf, 1);
        } else {
            v.prim = prim.data(), v.bu = bu.data(), v.bv = bv.data();
            kt.closest[int(ShapeKind::Mesh)](v, id.data(), &xf, 1);
        }
        return now() - t0;
    });
    if (hits) {
        *hits = 0;
        for (std::size_t i = 0; i < st.count; ++i) *hits += any ? (st.t_max[i] > 0 && t[i] == 0) : id[i] == 0;
    }
    return double(st.count) / sec * 1e-6;
}

}  // namespace streamrt::perf
