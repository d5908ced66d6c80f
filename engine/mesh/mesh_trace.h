#pragma once
// Scalar mesh queries (the baseline's, in double; tests also run them in float): the mesh's
// hierarchy walked with accel::traverse_closest / traverse_any, leaves tested with the
// watertight triangle test of shapes/triangle_math.h, and the normal at a hit.
#include <algorithm>
#include <cstdint>
#include <limits>

#include "accel/bvh.h"
#include "core/vec3.h"
#include "mesh/mesh.h"
#include "shapes/triangle_math.h"

namespace streamrt {

template <class T>
inline Vec3T<T> mesh_vertex(const MeshView& m, std::uint32_t tri, int j) {
    const float* p = triangle_corner(m, tri, j);
    return {T(p[0]), T(p[1]), T(p[2])};
}

/// Closest hit in (t_min, t_max) of the canonical ray (o, d) with the mesh; on a hit shrinks
/// t_max and sets the triangle and its barycentric coordinates (weights of p1 and p2).
template <class T>
inline bool mesh_closest(const MeshView& m, const accel::Bvh& bvh, const Vec3T<T>& o, const Vec3T<T>& d, T t_min,
                         T& t_max, std::uint32_t& tri, T& u, T& v) {
    if (m.n_tris == 0) return false;
    const WatertightRay<T> r = watertight_ray(o, d);
    bool hit = false;
    accel::traverse_closest<T>(bvh, o, d, t_max, [&](std::uint32_t first, std::uint32_t count, T& tm) {
        for (std::uint32_t k = first; k < first + count; ++k) {
            const TriangleHit<T> h =
                triangle_hit(r, mesh_vertex<T>(m, k, 0), mesh_vertex<T>(m, k, 1), mesh_vertex<T>(m, k, 2), t_min, tm);
            if (h.t < tm) {
                tm = h.t;
                tri = k;
                u = h.u;
                v = h.v;
                hit = true;
            }
        }
    });
    return hit;
}

/// One crossing of a line with a mesh's surface: where, on which triangle, and whether the
/// line enters the volume there (against the outward normal of a counter-clockwise triangle).
template <class T>
struct MeshCrossing {
    T t;
    std::uint32_t tri;
    bool enters;
};

/// The order of crossings along a line: by t, then by triangle.
template <class T>
inline bool mesh_crossing_before(const MeshCrossing<T>& a, const MeshCrossing<T>& b) {
    return a.t < b.t || (a.t == b.t && a.tri < b.tri);
}

/// Inserts c into out[0 .. n), kept sorted by mesh_crossing_before (an order that does not
/// depend on the walk's, so every walk keeps the same list); past capacity the farthest is let go.
template <class T>
inline void keep_crossing(MeshCrossing<T>* out, int& n, int capacity, const MeshCrossing<T>& c) {
    int i = n < capacity ? n++ : capacity;
    while (i > 0 && mesh_crossing_before(c, out[i - 1])) {
        if (i < capacity) out[i] = out[i - 1];
        --i;
    }
    if (i < capacity) out[i] = c;
}

/// The crossings of the whole line o + t d (every t) with the mesh, sorted by t: at most
/// `capacity`, the nearest to where the line enters the mesh's box. The hierarchy is walked
/// from that entry point (its walk covers t >= 0 only), every triangle of a visited leaf tested
/// over all t: the watertight test counts a line through an edge or a corner of a closed mesh
/// once. Returns the count.
template <class T>
inline int mesh_crossings(const MeshView& m, const accel::Bvh& bvh, const Vec3T<T>& o, const Vec3T<T>& d,
                          MeshCrossing<T>* out, int capacity) {
    if (m.n_tris == 0 || bvh.empty()) return 0;
    // The line's stretch through the mesh's box, over every t.
    T t0 = -std::numeric_limits<T>::infinity(), t1 = std::numeric_limits<T>::infinity();
    const T os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    for (int a = 0; a < 3; ++a) {
        const T lo = T(bvh.bounds.lo[a]), hi = T(bvh.bounds.hi[a]);
        if (ds[a] == T(0)) {
            if (os[a] < lo || os[a] > hi) return 0;
            continue;
        }
        const T ta = (lo - os[a]) / ds[a], tb = (hi - os[a]) / ds[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
    }
    if (!(t0 <= t1)) return 0;
    const Vec3T<T> start = o + d * t0;
    const WatertightRay<T> r = watertight_ray(start, d);
    const T inf = std::numeric_limits<T>::infinity();
    int n = 0;
    // The walk's boxes are padded; its t_max reaches past the exit by a margin for rounding.
    accel::traverse_any<T>(bvh, start, d, (t1 - t0) * T(1.0001) + T(1e-6), [&](std::uint32_t first, std::uint32_t count, T) {
        for (std::uint32_t k = first; k < first + count; ++k) {
            const Vec3T<T> p0 = mesh_vertex<T>(m, k, 0), p1 = mesh_vertex<T>(m, k, 1), p2 = mesh_vertex<T>(m, k, 2);
            const TriangleHit<T> h = triangle_hit(r, p0, p1, p2, -inf, inf);
            if (!(h.t < inf)) continue;
            const MeshCrossing<T> c{t0 + h.t, k, dot(d, triangle_normal(p0, p1, p2)) < T(0)};
            keep_crossing(out, n, capacity, c);
        }
        return false;  // every leaf the line passes
    });
    return n;
}

/// The barycentric coordinates (weights of p1 and p2) where the line o + t d, every t, crosses
/// triangle tri: a crossing mesh_crossings found, met again for the shading; the centroid if
/// rounding now lets the line pass beside it.
template <class T>
inline void mesh_crossing_uv(const MeshView& m, std::uint32_t tri, const Vec3T<T>& o, const Vec3T<T>& d, T& u, T& v) {
    const T inf = std::numeric_limits<T>::infinity();
    const TriangleHit<T> h = triangle_hit(watertight_ray(o, d), mesh_vertex<T>(m, tri, 0), mesh_vertex<T>(m, tri, 1),
                                          mesh_vertex<T>(m, tri, 2), -inf, inf);
    u = h.t < inf ? h.u : T(1) / T(3);
    v = h.t < inf ? h.v : T(1) / T(3);
}

/// True if some triangle is hit for t in (t_min, t_max).
template <class T>
inline bool mesh_any(const MeshView& m, const accel::Bvh& bvh, const Vec3T<T>& o, const Vec3T<T>& d, T t_min,
                     T t_max) {
    if (m.n_tris == 0) return false;
    const WatertightRay<T> r = watertight_ray(o, d);
    return accel::traverse_any<T>(bvh, o, d, t_max, [&](std::uint32_t first, std::uint32_t count, T tm) {
        for (std::uint32_t k = first; k < first + count; ++k)
            if (triangle_hit(r, mesh_vertex<T>(m, k, 0), mesh_vertex<T>(m, k, 1), mesh_vertex<T>(m, k, 2), t_min, tm)
                    .t < tm)
                return true;
        return false;
    });
}

/// Canonical-space normal (not unit) at barycentric (u, v) of triangle tri: the face normal,
/// or with `smooth` the vertex normals interpolated.
template <class T>
inline Vec3T<T> mesh_normal(const MeshView& m, std::uint32_t tri, T u, T v, bool smooth) {
    if (!smooth)
        return triangle_normal(mesh_vertex<T>(m, tri, 0), mesh_vertex<T>(m, tri, 1), mesh_vertex<T>(m, tri, 2));
    const auto vn = [&](int j) {
        const float* n = m.vertex_normals + 3 * std::size_t(m.index[3 * std::size_t(tri) + std::size_t(j)]);
        return Vec3T<T>{T(n[0]), T(n[1]), T(n[2])};
    };
    return vn(0) * (T(1) - u - v) + vn(1) * u + vn(2) * v;
}

}  // namespace streamrt
