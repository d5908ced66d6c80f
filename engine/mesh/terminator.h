#pragma once
// Terminator-safe shadow-ray origins on smooth-shaded triangles, after Hanika 2021 ("Hacking
// the shadow terminator", Ray Tracing Gems II ch. 4). A smooth mesh is shaded with its vertex
// normals interpolated, but its rays start on the flat triangles: near the terminator the
// shading normal still faces the light while the light is already below the flat triangle's
// neighbours, whose facets then shadow the point in jagged, triangle-shaped blotches. The
// shadow ray starts instead from a point on a curved patch through the triangle's corners:
// the hit point projected onto each corner's tangent plane, the projections blended with the
// hit's barycentrics. Written once for V = double (recursive engine), float and xsimd float
// batches (the stream engine's scalar and SIMD shade stages). docs/architecture.md,
// "Shadow terminator on smooth meshes".
#include <cstddef>
#include <cstdint>

#include "core/transform.h"
#include "core/vec3.h"
#include "mesh/mesh_view.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// A smooth triangle's corners in the mesh's canonical space: positions p[i] and vertex
/// normals n[i] (the mesh's, unit; the formula below does not need them unit).
template <class V>
struct SmoothCorners {
    Vec3T<V> p[3];
    Vec3T<V> n[3];
};

/// Triangle `tri` of a mesh as SmoothCorners (one ray; the SIMD kernel gathers lane by lane).
template <class T>
inline SmoothCorners<T> smooth_corners(const MeshView& m, std::uint32_t tri) {
    SmoothCorners<T> c;
    for (int j = 0; j < 3; ++j) {
        const float* p = triangle_corner(m, tri, j);
        const float* n = m.vertex_normals + 3 * std::size_t(m.index[3 * std::size_t(tri) + std::size_t(j)]);
        c.p[j] = {T(p[0]), T(p[1]), T(p[2])};
        c.n[j] = {T(n[0]), T(n[1]), T(n[2])};
    }
    return c;
}

/// The world-space vector that moves the hit at barycentrics (u, v) (weights of p[1] and p[2];
/// p[0] has 1 - u - v) of triangle c to its terminator-safe shadow origin, before the usual
/// offset (render/shading.h offset_ray_origin). `mi` is the object's Mi (rows, as for
/// apply_normal); `outside` says which side shadow rays leave from: along the vertex normals
/// (true) or against them (false, a ray that met the surface from inside).
///
/// With s = +-1 the side and b_i the barycentrics, corner i's tangent plane is the plane
/// through p_i with normal s n_i; the hit point p lies h_i = s dot(p - p_i, n_i) above it.
/// Only a point below the plane (h_i < 0) is projected onto it, q_i = p - h_i s n_i; a point
/// above it stays (q_i = p): the shift only ever lifts the point out of a convex patch, and
/// concave parts, where the flat triangle is already above the curved surface, keep the hit
/// point. p' = sum b_i q_i, so the shift is sum b_i max(0, -h_i) s n_i.
///
/// The projection is done in world space, where the tangent planes keep their meaning under a
/// non-uniform scale: corner i's world normal is m_i = Mn n_i (not unit), and since
/// p_w - P_i = Mi^-1 (p - p_i), the world height is dot(p - p_i, n_i) / |m_i| -- canonical
/// quantities only, so no Md is needed. World shift: sum b_i max(0, -h_i) s m_i / |m_i|^2.
/// p - p_i comes from the barycentrics and the triangle's edges, not from the ray: it is then
/// as precise as the triangle, wherever the ray started. Zero on flat normals (every h_i = 0).
template <class V, class Rows, class M>
inline Vec3T<V> terminator_shift(const Rows& mi, const SmoothCorners<V>& c, const V& u, const V& v, const M& outside) {
    using namespace simd;
    const Vec3T<V> e1 = c.p[1] - c.p[0], e2 = c.p[2] - c.p[0];
    const Vec3T<V> from0 = e1 * u + e2 * v;  // p - p0
    const Vec3T<V> from[3] = {from0, from0 - e1, from0 - e2};
    const V b[3] = {V(1) - u - v, u, v};
    const V s = select(outside, V(1), V(-1));
    Vec3T<V> shift{V(0), V(0), V(0)};
    for (int i = 0; i < 3; ++i) {
        const V depth = max(V(0), -(s * dot(from[i], c.n[i])));  // below the plane: > 0
        const Vec3T<V> m = normal_direction(mi, c.n[i]);
        shift = shift + m * (b[i] * depth / dot(m, m));
    }
    return shift * s;
}

STREAMRT_ISA_END
}  // namespace streamrt
