#pragma once
// Watertight ray/triangle intersection (Woop, Benthin & Wald 2013, "Watertight Ray/Triangle
// Intersection", JCGT 2(1)), written once for V = double (baseline), float and xsimd float
// batches (the mesh kernels).
//
// The ray is turned into a space where it starts at the origin and runs along +z: the axis
// of its largest direction component becomes z (kz), the other two x and y (swapped when
// d[kz] < 0 so the winding is kept), and a shear makes the direction (0, 0, 1). A vertex's
// sheared coordinates depend only on the vertex and the ray, so two triangles sharing an edge
// compute the same two products for it, in the same order, and their edge functions are
// exact negations of each other (round-to-nearest is symmetric; no FMA may be contracted
// here: the kernel files are built with -ffp-contract=off). A ray through a shared edge has
// that edge function exactly 0 in both triangles and is accepted by both; a ray beside it is
// accepted by exactly one. An edge function that rounds to 0 in float is recomputed in double
// (the products of two floats are exact in double), as the paper does.
#include <type_traits>

#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "simd/lanes.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// The per-ray part of the test, computed once per ray (or per packet of rays).
template <class V>
struct WatertightRay {
    using Mask = decltype(V(0) < V(0));
    Vec3T<V> o;
    Mask kx0, kx1, ky0, ky1, kz0, kz1;  ///< axis k of the permutation is 0, 1 (else 2)
    V sx, sy, sz;                        ///< shear constants
};

template <class V>
struct TriangleHit {
    V t;  ///< +inf on a miss
    V u;  ///< barycentric weight of p1
    V v;  ///< barycentric weight of p2 (p0 has 1 - u - v)
};

namespace tri_detail {
template <class V, class M>
inline V pick(const M& is0, const M& is1, const Vec3T<V>& a) {
    return simd::select(is0, a.x, simd::select(is1, a.y, a.z));
}

/// Recomputes in double the three edge functions of each lane (ray and triangle) that has
/// one exactly 0 in float; the other lanes keep theirs. Lane by lane, so a lane's answer does
/// not depend on the others: recomputing every lane once any had a zero made a ray's hit
/// depend on the packet it was traced in (a corner of adaptive sampling, traced in two
/// different packets by a whole image and by a tile rendered alone, came out an ulp apart).
template <class V>
inline void edge_fallback(V& U, V& Vv, V& W, const V& ax, const V& ay, const V& bx, const V& by, const V& cx,
                          const V& cy) {
    if constexpr (std::is_same_v<simd::scalar_t<V>, float>) {
        using simd::any;
        const auto zero = (U == V(0.f)) || (Vv == V(0.f)) || (W == V(0.f));
        if (!any(zero)) return;
        if constexpr (std::is_same_v<V, float>) {
            U = float(double(cx) * double(by) - double(cy) * double(bx));
            Vv = float(double(ax) * double(cy) - double(ay) * double(cx));
            W = float(double(bx) * double(ay) - double(by) * double(ax));
        } else {
            constexpr std::size_t N = V::size;
            alignas(64) float a[6][N], out[3][N];
            ax.store_aligned(a[0]);
            ay.store_aligned(a[1]);
            bx.store_aligned(a[2]);
            by.store_aligned(a[3]);
            cx.store_aligned(a[4]);
            cy.store_aligned(a[5]);
            for (std::size_t l = 0; l < N; ++l) {
                const double Ax = a[0][l], Ay = a[1][l], Bx = a[2][l], By = a[3][l], Cx = a[4][l], Cy = a[5][l];
                out[0][l] = float(Cx * By - Cy * Bx);
                out[1][l] = float(Ax * Cy - Ay * Cx);
                out[2][l] = float(Bx * Ay - By * Ax);
            }
            U = simd::select(zero, V::load_aligned(out[0]), U);
            Vv = simd::select(zero, V::load_aligned(out[1]), Vv);
            W = simd::select(zero, V::load_aligned(out[2]), W);
        }
    }
}
}  // namespace tri_detail

/// Sets up the ray (origin o, direction d, not necessarily unit) for triangle tests.
template <class V>
inline WatertightRay<V> watertight_ray(const Vec3T<V>& o, const Vec3T<V>& d) {
    using namespace simd;
    WatertightRay<V> r;
    r.o = o;
    const V ax = abs(d.x), ay = abs(d.y), az = abs(d.z);
    const auto z0 = (ax >= ay) && (ax >= az);
    const auto z1 = !z0 && (ay >= az);
    const auto z2 = !z0 && !z1;
    const V dz = select(z0, d.x, select(z1, d.y, d.z));
    const auto neg = dz < V(0);
    const auto pos = !neg;
    // Nominal kx = kz + 1, ky = kz + 2 (mod 3); swapped when d[kz] < 0.
    r.kz0 = z0;
    r.kz1 = z1;
    r.kx0 = (z2 && pos) || (z1 && neg);
    r.kx1 = (z0 && pos) || (z2 && neg);
    r.ky0 = (z1 && pos) || (z2 && neg);
    r.ky1 = (z2 && pos) || (z0 && neg);
    const V dx = tri_detail::pick(r.kx0, r.kx1, d);
    const V dy = tri_detail::pick(r.ky0, r.ky1, d);
    r.sz = V(1) / dz;
    r.sx = dx * r.sz;
    r.sy = dy * r.sz;
    return r;
}

namespace tri_detail {
/// The edge functions of the sheared triangle, its determinant and scaled distance (t = T / det).
template <class V>
struct Sheared {
    V U, Vv, W, det, T;
    decltype(V(0) < V(0)) inside;  ///< the ray passes through the triangle or its border
};
/// The test proper up to the division, on the corners relative to the ray's origin and
/// already permuted (x: axis kx, y: ky, z: kz). triangle_sheared() permutes with per-lane
/// selects (a packet's rays may differ in kz); the single-ray walk, whose one ray fixes the
/// axes, loads the permuted coordinates of 4 triangles directly (kernels/mesh_single_kernel.h).
/// Same operations in the same order either way, so both give the same bits. The rest of the
/// test: triangle_hit_sheared (the division: t, u, v), triangle_may_hit (which lanes may hit,
/// without it), triangle_blocks_sheared (any hit, without it).
template <class V>
[[gnu::always_inline]] inline Sheared<V> shear(const WatertightRay<V>& r, const Vec3T<V>& a, const Vec3T<V>& b,
                                               const Vec3T<V>& c) {
    const V ax = a.x - r.sx * a.z, ay = a.y - r.sy * a.z;
    const V bx = b.x - r.sx * b.z, by = b.y - r.sy * b.z;
    const V cx = c.x - r.sx * c.z, cy = c.y - r.sy * c.z;
    V U = cx * by - cy * bx;
    V Vv = ax * cy - ay * cx;
    V W = bx * ay - by * ax;
    edge_fallback(U, Vv, W, ax, ay, bx, by, cx, cy);
    const auto outside = ((U < V(0)) || (Vv < V(0)) || (W < V(0))) && ((U > V(0)) || (Vv > V(0)) || (W > V(0)));
    const V det = U + Vv + W;
    const V T = U * (r.sz * a.z) + Vv * (r.sz * b.z) + W * (r.sz * c.z);
    return {U, Vv, W, det, T, !outside};
}

/// The ray passes through the triangle at some t > 0: inside its edges, and T and det of one
/// sign (t = T / det). What is left is the comparison with t_max.
template <class V>
inline auto ahead(const Sheared<V>& s) {
    const auto same_sign = ((s.T > V(0)) && (s.det > V(0))) || ((s.T < V(0)) && (s.det < V(0)));
    return s.inside && same_sign;
}
}  // namespace tri_detail

/// The rest of the test on a sheared triangle (tri_detail::shear): the division, t, u, v,
/// for t in (t_min, t_max), or (t_min, t_max] when `with_tie` (the mesh walks' closest hit,
/// which settles a tie between two triangles by their numbers: mesh_kernel.h).
template <bool with_tie = false, class V>
inline TriangleHit<V> triangle_hit_sheared(const tri_detail::Sheared<V>& s, V t_min, V t_max) {
    using namespace simd;
    const auto ok = s.inside && (s.det != V(0));
    const V inv_det = V(1) / select(ok, s.det, V(1));
    const V t = s.T * inv_det;
    const auto hit = ok && (t > t_min) && (with_tie ? t <= t_max : t < t_max);
    return {select(hit, t, infinity_v<V>()), s.Vv * inv_det, s.W * inv_det};
}

/// A superset of the lanes that triangle_hit_sheared(s, 0, t_max) finds a hit on, without its
/// division: the closest-hit walks skip the division for triangles no lane can hit (most of the
/// triangles they test). T / det in (0, t_max) needs T and det of one sign and |T| < t_max |det|;
/// the slack of 2^-20 covers the roundings of both forms (t rounds twice, the product once: a
/// few times 2^-24 apart), so a lane the exact test accepts always passes here.
template <class V>
inline auto triangle_may_hit(const tri_detail::Sheared<V>& s, V t_max) {
    using namespace simd;
    return tri_detail::ahead(s) && (abs(s.T) <= (t_max * abs(s.det)) * V(1 + 0x1p-20));
}

/// Whether the triangle blocks the ray for t in (0, t_max), without the division: t = T / det
/// lies in (0, t_max) when T and det have one sign and |T| < t_max |det|. The any-hit walks
/// need no distance, and the division was their triangle test's slowest instruction (a
/// 16-lane divide per triangle and packet). The comparison rounds once (the product), where
/// T * (1 / det) < t_max rounds twice, so the two may differ for a hit within an ulp or two of
/// t_max; the walks' tests grant any-hit that margin (tests/meshes/mesh_walk_test.cpp).
template <class V>
inline auto triangle_blocks_sheared(const tri_detail::Sheared<V>& s, V t_max) {
    using namespace simd;
    return tri_detail::ahead(s) && (abs(s.T) < t_max * abs(s.det));
}
template <class V>
inline auto triangle_blocks_permuted(const WatertightRay<V>& r, const Vec3T<V>& a, const Vec3T<V>& b,
                                     const Vec3T<V>& c, V t_max) {
    return triangle_blocks_sheared(tri_detail::shear(r, a, b, c), t_max);
}

/// The triangle (p0, p1, p2) sheared for the ray: each corner relative to the ray's origin,
/// permuted to the ray's axes (per lane, with selects).
template <class V>
inline tri_detail::Sheared<V> triangle_sheared(const WatertightRay<V>& r, const Vec3T<V>& p0, const Vec3T<V>& p1,
                                               const Vec3T<V>& p2) {
    using tri_detail::pick;
    const auto permuted = [&r](const Vec3T<V>& p) {
        return Vec3T<V>{pick(r.kx0, r.kx1, p), pick(r.ky0, r.ky1, p), pick(r.kz0, r.kz1, p)};
    };
    return tri_detail::shear(r, permuted(p0 - r.o), permuted(p1 - r.o), permuted(p2 - r.o));
}

/// Nearest hit in (t_min, t_max) with the triangle (p0, p1, p2), t = +inf on a miss. Both
/// faces count. t is measured along the direction given to watertight_ray().
template <class V>
inline TriangleHit<V> triangle_hit(const WatertightRay<V>& r, const Vec3T<V>& p0, const Vec3T<V>& p1,
                                   const Vec3T<V>& p2, V t_min, V t_max) {
    return triangle_hit_sheared(triangle_sheared(r, p0, p1, p2), t_min, t_max);
}

/// triangle_blocks_sheared on the triangle (p0, p1, p2).
template <class V>
inline auto triangle_blocks(const WatertightRay<V>& r, const Vec3T<V>& p0, const Vec3T<V>& p1, const Vec3T<V>& p2,
                            V t_max) {
    return triangle_blocks_sheared(triangle_sheared(r, p0, p1, p2), t_max);
}

/// Unnormalised geometric normal (p1 - p0) x (p2 - p0): outward for counter-clockwise
/// triangles seen from outside (the OBJ convention).
template <class V>
inline Vec3T<V> triangle_normal(const Vec3T<V>& p0, const Vec3T<V>& p1, const Vec3T<V>& p2) {
    return cross(p1 - p0, p2 - p0);
}

STREAMRT_ISA_END
}  // namespace streamrt
