#pragma once
// Shared root finding for the quadric shapes.
#include <cmath>
#include <limits>

#include "core/vec3.h"
#include "shapes/shape_traits.h"
#include "simd/lanes.h"
#include "simd/stable_math.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

template <class V>
inline V infinity_v() {
    return V(std::numeric_limits<simd::scalar_t<V>>::infinity());
}

/// Roots of a t^2 + 2 b t + c = 0 given disc = b^2 - a c computed by the caller (who can
/// often compute it without cancellation). Uses q = -(b + sign(b) sqrt(disc)), t = q/a and
/// t = c/q, which never subtracts nearly equal numbers (Numerical Recipes 5.6). a may be 0
/// (a linear equation): then q/a is +-inf and c/q is the one root. Lanes with disc < 0 or
/// NaN have `valid` false. Returns the roots unordered.
template <class V>
struct QuadraticRoots {
    V t0, t1;
    decltype(V(0) < V(0)) valid;
};

template <class V>
inline QuadraticRoots<V> solve_quadratic(V a, V b, V c, V disc) {
    using namespace simd;
    const auto valid = disc >= V(0);  // false on NaN, on purpose
    const V root = sqrt(select(valid, disc, V(0)));
    const V q = -(b + sign_of(b) * root);
    return {q / a, c / q, valid};
}

/// Keeps, per lane, the smallest candidate t with ok && t_min < t < best. NaN never wins.
template <class V, class M>
inline V keep_closest(V best, V t, M ok, V t_min) {
    using namespace simd;
    return select(ok && (t > t_min) && (t < best), t, best);
}

/// The unit disc in the plane y = level (a cylinder's or cone's cap): keeps its crossing
/// when it lies inside the disc. dy = 0 gives +-inf or NaN, which fail the test.
template <class V>
inline V keep_cap(V best, const Vec3T<V>& o, const Vec3T<V>& d, V level, V t_min) {
    const V t = (level - o.y) / d.y;
    const V x = o.x + d.x * t, z = o.z + d.z * t;
    return keep_closest(best, t, x * x + z * z <= V(1), t_min);
}

/// The texture coordinate of an angle around the y axis: 0.5 + atan2(x, z) / (2 pi), so
/// u = 0.5 on +z, 0.75 on +x, 0 and 1 on -z (the seam, where the lookup wraps).
/// atan2 is simd/stable_math.h's (the same bits at every ISA level, within 2.9e-9 rad).
template <class V>
inline V uv_angle(const V& x, const V& z) {
    return V(0.5) + simd::stable_atan2(x, z) * V(0.15915494309189535);
}

/// Planar coordinates of the square [-1, 1]^2 in [0, 1]^2: ((a + 1) / 2, (b + 1) / 2).
template <class V>
inline UvT<V> uv_square(const V& a, const V& b) {
    return {(a + V(1)) * V(0.5), (b + V(1)) * V(0.5)};
}

/// best started at t_max; lanes that kept it report a miss (+inf).
template <class V>
inline V miss_if_unchanged(V best, V t_max) {
    using namespace simd;
    return select(best < t_max, best, infinity_v<V>());
}

STREAMRT_ISA_END
}  // namespace streamrt
