#pragma once
// sin/cos, atan2 and log2 written once for scalars (float, double) and xsimd float batches,
// as short truncated series with plain multiplies, adds and divides (never fused: the kernel
// files are built with -ffp-contract=off, see simd/lanes.h mul_add), so every ISA level and
// the scalar float path give the same bits; xsimd's versions round differently at different
// levels. Used by the lens and area-light sampling (render/sampling.h, render/shading.h) and
// the texture lookups (shapes' uv<V>, render/texture.h texture_lod).
//
// Error bounds (truncation; the tests check them in double against std::, float evaluation
// adds a few roundings of the result's size):
//   sin_cos_quarter: |error| <= (pi/4)^11 / 11! < 1.8e-9 (sin), (pi/4)^12 / 12! < 1.2e-10 (cos)
//                    (tests/render/area_light_test.cpp, through cos_sin_of_turn)
//   stable_atan2:    |error| <= (2 - sqrt 3)^13 / 13 < 2.9e-9 rad   (tests/simd/stable_math_test.cpp)
//   stable_log2:     |error| <= 2 s^11 / (11 (1 - s^2) ln 2) < 1.1e-9, s = 3 - 2 sqrt 2
#include <xsimd/xsimd.hpp>

#include <cmath>
#include <cstdint>

#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt::simd {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// atan t for |t| <= tan(pi / 12) = 2 - sqrt 3: the Taylor series through t^11. The series
/// alternates with decreasing terms, so the error is below the first term left out,
/// |t|^13 / 13 <= (2 - sqrt 3)^13 / 13 < 2.9e-9.
template <class V>
inline V atan_series(const V& t) {
    const V z = t * t;
    const V p = V(-1.0 / 3.0) + z * (V(1.0 / 5.0) + z * (V(-1.0 / 7.0) + z * (V(1.0 / 9.0) + z * V(-1.0 / 11.0))));
    return t + t * z * p;
}

/// atan2(y, x) in [-pi, pi]: a = min(|x|, |y|) / max(|x|, |y|) in [0, 1], reduced to
/// |t| <= 2 - sqrt 3 by atan a = pi/6 + atan((a sqrt 3 - 1) / (a + sqrt 3)) above 2 - sqrt 3,
/// then folded back to the octant of (x, y). atan2(0, 0) = 0; x = -0 counts as +0 (u = 0.5
/// rather than 1 at a pole, the same texel); NaN in, NaN out.
template <class V>
inline V stable_atan2(const V& y, const V& x) {
    const V ax = abs(x), ay = abs(y);
    const V hi = max(ax, ay), lo = min(ax, ay);
    const V a = select(hi > V(0), lo / hi, V(0));
    const auto big = a > V(0.2679491924311227);  // 2 - sqrt 3
    const V t = select(big, (a * V(1.7320508075688772) - V(1)) / (a + V(1.7320508075688772)), a);
    V r = atan_series(t);
    r = select(big, V(0.5235987755982988) + r, r);  // + pi/6
    r = select(ay > ax, V(1.5707963267948966) - r, r);
    r = select(x < V(0), V(3.141592653589793) - r, r);
    r = select(y < V(0), -r, r);
    return select(x == x && y == y, r, x + y);  // NaN, the same at every level (min/max differ)
}

/// x = m 2^e with m in [1, 2), exactly, for x finite and > 0 and normal.
inline void split_exponent(float x, float& m, float& e) {
    int k = 0;
    m = 2.f * std::frexp(x, &k);
    e = float(k - 1);
}
inline void split_exponent(double x, double& m, double& e) {
    int k = 0;
    m = 2.0 * std::frexp(x, &k);
    e = double(k - 1);
}
template <class A>
inline void split_exponent(const xsimd::batch<float, A>& x, xsimd::batch<float, A>& m, xsimd::batch<float, A>& e) {
    using I = xsimd::batch<std::int32_t, A>;
    const I bits = xsimd::bitwise_cast<I>(x);
    e = xsimd::to_float((bits >> 23) - I(127));
    m = xsimd::bitwise_cast<xsimd::batch<float, A>>((bits & I(0x007fffff)) | I(0x3f800000));
}

/// log2 x for x finite, normal and > 0: x = m 2^e with m in [sqrt(1/2), sqrt 2), and
/// ln m = 2 atanh s, s = (m - 1) / (m + 1), |s| <= 3 - 2 sqrt 2, by its series through s^9:
/// the terms left out sum to at most 2 |s|^11 / (11 (1 - s^2)), under 1.1e-9 in log2.
/// Exactly 0 at x = 1 and exactly k at x = 2^k.
template <class V>
inline V stable_log2(const V& x) {
    V m, e;
    split_exponent(x, m, e);
    const auto high = m > V(1.4142135623730951);
    m = select(high, m * V(0.5), m);
    e = select(high, e + V(1), e);
    const V s = (m - V(1)) / (m + V(1));
    const V z = s * s;
    const V p = V(1) + z * (V(1.0 / 3.0) + z * (V(1.0 / 5.0) + z * (V(1.0 / 7.0) + z * V(1.0 / 9.0))));
    return e + s * p * V(2.8853900817779268);  // 2 / ln 2
}

/// sin and cos on [-pi/4, pi/4] by their Taylor polynomials (errors below 2e-9 and 1.2e-10),
/// with plain multiplies and adds: the same bits in scalar float and at every SIMD level,
/// where xsimd's sin/cos would round differently from one level to the next. V is float,
/// double (the recursive engine) or a float batch.
template <class V>
inline void sin_cos_quarter(const V& a, V& s, V& c) {
    using S = scalar_t<V>;
    const V a2 = a * a;
    s = a * (V(S(1)) + a2 * (V(S(-1.0 / 6)) + a2 * (V(S(1.0 / 120)) + a2 * (V(S(-1.0 / 5040)) +
                                                                             a2 * V(S(1.0 / 362880))))));
    c = V(S(1)) + a2 * (V(S(-0.5)) + a2 * (V(S(1.0 / 24)) + a2 * (V(S(-1.0 / 720)) + a2 * (V(S(1.0 / 40320)) +
                                                                                       a2 * V(S(-1.0 / 3628800))))));
}

/// cos and sin of the angle 2 pi u, u in [0, 1) (the sphere light's azimuth): the nearest
/// quarter turn q is taken off exactly, the rest (within an eighth of a turn) goes through
/// sin_cos_quarter, and the quarter turns rotate (cos, sin) by swaps and sign changes, which
/// are exact.
template <class V>
inline void cos_sin_of_turn(const V& u, V& c, V& s) {
    using std::floor;
    using S = scalar_t<V>;
    const V x = u * V(S(4));
    const V q = floor(x + V(S(0.5)));  // 0 .. 4; x - q is exact, in [-0.5, 0.5]
    V st, ct;
    sin_cos_quarter((x - q) * V(S(1.5707963267948966)), st, ct);
    const auto odd = (q == V(S(1))) || (q == V(S(3)));
    const auto back = (q == V(S(2))) || (q == V(S(3)));
    const V c0 = select(odd, -st, ct), s0 = select(odd, ct, st);
    c = select(back, -c0, c0);
    s = select(back, -s0, s0);
}

STREAMRT_ISA_END
}  // namespace streamrt::simd
