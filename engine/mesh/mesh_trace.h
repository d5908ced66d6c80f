#pragma once
// Scalar mesh queries (the baseline's, in double; tests also run them in float): the mesh's
// hierarchy walked with accel::traverse_closest / traverse_any, leaves tested with the
// watertight triangle test of shapes/triangle_math.h, and the normal at a hit.
#include <cstdint>

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
