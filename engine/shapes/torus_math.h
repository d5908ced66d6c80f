#pragma once
// Canonical torus: ring of major radius R = 1 around the y axis in the xz plane, tube of
// radius r = `minor` (any r > 0: thin, fat and self-intersecting "spindle" r > 1).
//
//   F(p) = (|p|^2 + 1 - r^2)^2 - 4 (x^2 + z^2)
//        = ((rho - 1)^2 + y^2 - r^2) * ((rho + 1)^2 + y^2 - r^2),   rho = sqrt(x^2 + z^2).
//
// Written once for V = double (baseline renderer), V = xsimd::batch<double, A> (stream
// kernels) and V = float. Branch-free on lanes: every loop has a fixed trip count and the
// only data-dependent branch is the "no lane can hit" early out. See docs/torus.md.
//
// Method (per lane):
//   1. reject NaN/inf/zero/denormal input; normalise d (scaled by its largest component so
//      tiny and huge directions work) and remember |d| to rescale t at the end;
//   2. if the origin is far (|o| > 2(1+r)) move it to the ray's closest approach to the
//      centre, so the quartic is built from coordinates of size <= 1 + r;
//   3. clip the ray to the bounding sphere |p| <= 1 + r, the slab |y| <= r and (t_min, t_max);
//   4. split the clipped interval into <= 4 pieces on which the quartic is monotone: the
//      roots of f'' (closed-form quadratic) bracket the <= 3 roots of f' (cubic), each found
//      by a safeguarded Newton/bisection;
//   5. take the first piece whose end points have opposite signs of F (evaluated in the
//      factored, cancellation-free form) and solve it with safeguarded Newton/bisection on the
//      factored F, which doubles as the final Newton polish.
#include <algorithm>
#include <array>
#include <limits>

#include "core/vec3.h"
#include "shapes/shape_traits.h"
#include "shapes/solid_span.h"
#include "shapes/quadratic.h"
#include "simd/lanes.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

namespace torus_detail {

template <class V>
using mask_t = decltype(V() < V());

/// Iteration counts of the safeguarded Newton/bisection solves (fixed so lanes stay in step).
inline constexpr int kCriticalIters = 20;
inline constexpr int kRootIters = 28;

/// When a bracket_solve lane stops: a step (any kind) at most `step` times |x|, or a Newton step
/// at most `newton_step` times |x| (quadratic convergence: the error left is ~ C newton_step^2).
struct SolveTol {
    double step, newton_step;
};

/// The critical points only place the piece ends where F's sign is read, and F is flat there
/// (an error d in the point moves F by ~F'' d^2 / 2), so 1e-10 relative is ample.
inline constexpr SolveTol kCriticalTol{1e-10, 1e-7};
/// The root: a few ulps, or a Newton step below 1e-9 relative (error left ~ C 1e-18).
template <class S>
inline constexpr SolveTol kRootTol{8 * double(std::numeric_limits<S>::epsilon()), 1e-9};

template <class V>
inline V inf_v() { return V(std::numeric_limits<simd::scalar_t<V>>::infinity()); }

/// |a| is finite (false for NaN and +-inf).
template <class V>
inline mask_t<V> finite(const V& a) {
    return simd::abs(a) <= V(std::numeric_limits<simd::scalar_t<V>>::max());
}

/// Safeguarded Newton/bisection on N independent brackets [a[j], b[j]] at once, where
/// fn(a[j]) has sign neg_a[j] (true: negative) and fn(b[j]) the other sign, for the lanes in
/// active[j]; the others are frozen from the start (a lane without a bracket would otherwise
/// bisect towards an end for all `iters` steps and hold its whole packet back). fn(x, f, df)
/// evaluates the function and its derivative. Newton steps are taken when they stay in the
/// (shrinking) bracket and at least halve the previous step, otherwise the bracket is
/// bisected. The first point is start[j] (inside the bracket). Writes to out[j] the evaluated
/// point with the smallest |f|.
///
/// Each step is a chain of dependent operations (evaluate, divide, compare, select), so a
/// single solve is bound by latency; the N solves share one loop so that their chains overlap.
///
/// A lane stops (is frozen, its values no longer updated) once its step falls to a few ulps;
/// the loop ends when every lane of every bracket has stopped or after `iters` steps. Freezing
/// rather than merely exiting makes a lane's answer independent of its neighbours and of the
/// other brackets: a ray gets the same bits alone (V = double) as in any batch.
template <int N, class V, class Fn>
inline void bracket_solve(V (&a)[N], V (&b)[N], const mask_t<V> (&neg_a)[N], const mask_t<V> (&active)[N],
                          const V (&start)[N], const SolveTol& st, Fn&& fn, int iters, V (&out)[N]) {
    // Never below a few ulps of the lane type (float lanes).
    using S = simd::scalar_t<V>;
    const S few_ulps = S(8) * std::numeric_limits<S>::epsilon();
    const V tol(std::max(S(st.step), few_ulps)), tol_newton(std::max(S(st.newton_step), few_ulps));
    V x[N], step_old[N], best[N], best_f[N];
    mask_t<V> live[N];
    for (int j = 0; j < N; ++j) {
        x[j] = start[j];
        step_old[j] = simd::abs(b[j] - a[j]);
        best[j] = x[j];
        best_f[j] = inf_v<V>();
        live[j] = active[j];
    }
    for (int i = 0; i < iters; ++i) {
        mask_t<V> any_live = live[0];
        for (int j = 0; j < N; ++j) {
            // Often only one bracket has lanes left: skip the others' division (the divider,
            // not the chain, is then the bottleneck).
            if (!simd::any(live[j])) continue;
            V f, df;
            fn(x[j], f, df);
            const V af = simd::abs(f);
            const auto better = live[j] & (af < best_f[j]);
            best[j] = simd::select(better, x[j], best[j]);
            best_f[j] = simd::select(better, af, best_f[j]);
            // Same sign as at a: the root lies right of x.
            const auto right = !simd::mask_xor(f < V(0), neg_a[j]);
            a[j] = simd::select(live[j] & right, x[j], a[j]);
            b[j] = simd::select(live[j] & !right, x[j], b[j]);
            const V step = f / df;
            const V xn = x[j] - step;
            const auto newton_ok = (xn >= a[j]) & (xn <= b[j]) & (simd::abs(step) * V(2) <= step_old[j]);
            const V xnew = simd::select(newton_ok, xn, (a[j] + b[j]) * V(0.5));
            const V moved = simd::abs(xnew - x[j]);
            step_old[j] = simd::select(live[j], moved, step_old[j]);
            x[j] = simd::select(live[j], xnew, x[j]);
            const V ax = simd::abs(x[j]);
            // A Newton step of relative size m leaves an error ~ C m^2: below tol_newton the
            // next step would be lost in rounding, so stop now. NaN steps stop too.
            live[j] = live[j] & (moved > tol * ax) & !(newton_ok & (moved <= tol_newton * ax));
            any_live = any_live | live[j];
        }
        if (!simd::any(any_live)) break;
    }
    for (int j = 0; j < N; ++j) {
        V f, df;
        fn(x[j], f, df);
        out[j] = simd::select(simd::abs(f) < best_f[j], x[j], best[j]);
    }
}

/// First guess in a bracket [u, v] with f(u), f(v) of opposite signs: where the chord crosses
/// zero (closer to the root than the midpoint when f is nearly linear, as it is once the
/// bracket is a monotone piece), clamped into the bracket against rounding; the midpoint for
/// lanes without a bracket.
template <class V>
inline V false_position(const V& u, const V& v, const V& fu, const V& fv, const mask_t<V>& bracketed) {
    const V mid = (u + v) * V(0.5);
    const V den = simd::select(bracketed, fu - fv, V(1));
    const V x = u + (v - u) * (fu / den);
    const V lo = simd::min(u, v), hi = simd::max(u, v);
    return simd::select(bracketed & (x >= lo) & (x <= hi), x, mid);
}

template <class V>
struct Factored {
    V f, df;
};

/// F and dF/ds at p = p0 + s*D. F in the factored form; dF/ds = 4 q (p.D) - 8 (x Dx + z Dz).
template <class V>
inline void torus_f(const Vec3T<V>& p0, const Vec3T<V>& D, const V& r2, const V& s, V& f, V& df) {
    const V x = p0.x + s * D.x;
    const V y = p0.y + s * D.y;
    const V z = p0.z + s * D.z;
    const V rho2 = x * x + z * z;
    const V rho = simd::sqrt(rho2);
    const V yr = y * y - r2;
    const V g1 = (rho - V(1)) * (rho - V(1)) + yr;
    const V g2 = (rho + V(1)) * (rho + V(1)) + yr;
    f = g1 * g2;
    const V q = rho2 + yr + V(1);
    df = V(4) * q * (x * D.x + y * D.y + z * D.z) - V(8) * (x * D.x + z * D.z);
}

}  // namespace torus_detail

/// Steps 1 - 4 of the method for a line o + t d, t in (t_min, t_max): the line in the torus's
/// frame (s = t len - tc along the unit D from p0) and the <= 4 monotone pieces of F between
/// pts[0..4], with F and its sign at each end. `valid`: the lanes whose clipped line is not
/// empty.
template <class V>
struct TorusPieces {
    torus_detail::mask_t<V> valid;
    Vec3T<V> p0, D;
    V r2, tc, len;
    V pts[5], fpts[5];
    torus_detail::mask_t<V> neg[5];
};

/// Fills `tp` (TorusPieces); false when no lane is valid (tp then holds only `valid`).
template <class V>
bool torus_pieces(const Vec3T<V>& o, const Vec3T<V>& d, V minor, V t_min, V t_max, TorusPieces<V>& tp) {
    using namespace torus_detail;
    using S = simd::scalar_t<V>;
    using M = mask_t<V>;
    const V inf = inf_v<V>();
    const V zero(0), one(1);

    // 1. Validate and normalise the direction.
    const V m = simd::max(simd::abs(d.x), simd::max(simd::abs(d.y), simd::abs(d.z)));
    M valid = finite(o.x) & finite(o.y) & finite(o.z) & finite(m) &
              (m >= V(std::numeric_limits<S>::min())) & finite(minor) &
              (minor > V(std::numeric_limits<S>::min())) & !(t_min != t_min) & !(t_max != t_max);
    // Invalid lanes compute on harmless stand-ins so no NaN travels through the arithmetic.
    const V ms = simd::select(valid, m, one);
    const V inv_m = one / ms;
    const Vec3T<V> dm{simd::select(valid, d.x * inv_m, one), simd::select(valid, d.y * inv_m, zero),
                      simd::select(valid, d.z * inv_m, zero)};
    const V lm = simd::sqrt(dot(dm, dm));  // in [1, sqrt 3]
    const V inv_lm = one / lm;
    const Vec3T<V> D = dm * inv_lm;
    const V len = ms * lm;  // |d|; may overflow to inf
    valid = valid & finite(len);
    const V r = simd::select(valid, minor, one);
    const V r2 = r * r;
    // Bounding sphere and slab, padded by a relative 2^-20 so that rays whose roots lie
    // exactly on them (radial rays through the outer equator, grazing the top) start from a
    // point safely outside the surface.
    const V pad(1.0 + 1.0 / 1048576.0);
    const V B = (one + r) * pad;
    const V B2 = B * B;
    const V r_slab = r * pad;

    // 2. Move a far origin to the closest approach to the centre (s = t*len - tc).
    Vec3T<V> oo{simd::select(valid, o.x, zero), simd::select(valid, o.y, zero), simd::select(valid, o.z, zero)};
    const M far = dot(oo, oo) > V(4) * B2;
    V tc = simd::select(far, -dot(oo, D), zero);
    Vec3T<V> p0 = oo + D * tc;
    const V tc2 = simd::select(far, -dot(p0, D), zero);  // one refinement pass
    p0 = p0 + D * tc2;
    tc = tc + tc2;

    // 3. Clip to the bounding sphere, the slab |y| <= r and (t_min, t_max).
    const V b = dot(p0, D);
    const V c = dot(p0, p0);
    const V disc = b * b - (c - B2);
    valid = valid & (disc >= zero);
    const V w = simd::sqrt(simd::max(disc, zero));
    V lo = -b - w;
    V hi = -b + w;
    {
        const V inv_dy = one / D.y;
        const V s1 = (-r_slab - p0.y) * inv_dy;
        const V s2 = (r_slab - p0.y) * inv_dy;
        const M flat = D.y == zero;
        const M in_slab = simd::abs(p0.y) <= r_slab;
        const V sl = simd::select(flat, simd::select(in_slab, -inf, inf), simd::min(s1, s2));
        const V sh = simd::select(flat, simd::select(in_slab, inf, -inf), simd::max(s1, s2));
        lo = simd::max(lo, sl);
        hi = simd::min(hi, sh);
    }
    {
        const V smin = simd::select(valid, t_min, zero) * len - tc;
        const V smax = simd::select(valid, t_max, zero) * len - tc;
        lo = simd::max(lo, smin);
        hi = simd::min(hi, smax);
    }
    valid = valid & (lo <= hi);
    tp.valid = valid;
    if (!simd::any(valid)) return false;
    lo = simd::select(valid, lo, zero);
    hi = simd::select(valid, hi, zero);

    // 4. Quartic f(s) = s^4 + A3 s^3 + A2 s^2 + A1 s + A0 and its critical points.
    const V e = c + (one - r2);
    const V a2 = D.x * D.x + D.z * D.z;
    const V a1 = p0.x * D.x + p0.z * D.z;
    const V A3 = V(4) * b;
    const V A2 = V(4) * b * b + V(2) * e - V(4) * a2;
    const V A1 = V(4) * b * e - V(8) * a1;
    const V C2 = V(3) * A3, C1 = V(2) * A2;  // f'(s) = 4 s^3 + C2 s^2 + C1 s + A1
    auto fprime = [&](const V& s, V& f1, V& f2) {
        f1 = ((V(4) * s + C2) * s + C1) * s + A1;
        f2 = (V(12) * s + V(2) * C2) * s + C1;
    };
    // Roots of f''(s) = 12 s^2 + 6 A3 s + 2 A2: s = -b +- simd::sqrt(b^2 - A2/6).
    const V hq = simd::sqrt(simd::max(b * b - A2 * V(1.0 / 6.0), zero));
    const V q1 = simd::min(simd::max(-b - hq, lo), hi);
    const V q2 = simd::min(simd::max(-b + hq, lo), hi);
    // The three pieces [lo, q1], [q1, q2], [q2, hi] are solved together (independent chains).
    V cu[3] = {lo, q1, q2}, cv[3] = {q1, q2, hi}, k[3];
    V cstart[3];
    M cneg[3], cchange[3];
    for (int j = 0; j < 3; ++j) {
        V fu, fv, dummy;
        fprime(cu[j], fu, dummy);
        fprime(cv[j], fv, dummy);
        cneg[j] = fu < zero;
        cchange[j] = simd::mask_xor(cneg[j], fv < zero);
        cstart[j] = false_position(cu[j], cv[j], fu, fv, cchange[j]);
    }
    const V cend[3] = {cv[0], cv[1], cv[2]};
    bracket_solve(cu, cv, cneg, cchange, cstart, kCriticalTol, fprime, kCriticalIters, k);
    const V k1 = simd::select(cchange[0], k[0], cend[0]);
    const V k2 = simd::select(cchange[1], k[1], cend[1]);
    const V k3 = simd::select(cchange[2], k[2], cend[2]);

    // The pieces' ends, and F there.
    tp.p0 = p0;
    tp.D = D;
    tp.r2 = r2;
    tp.tc = tc;
    tp.len = len;
    const V pts[5] = {lo, k1, k2, k3, hi};
    for (int i = 0; i < 5; ++i) {
        V df;
        tp.pts[i] = pts[i];
        torus_f(p0, D, r2, pts[i], tp.fpts[i], df);
        tp.neg[i] = tp.fpts[i] < zero;
    }
    return true;
}

/// Nearest t in (t_min, t_max) with o + t*d on the torus (d need NOT be unit length), or
/// +infinity for a miss. NaN/inf inputs give a miss (+inf), never NaN.
template <class V>
V torus_hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V minor, V t_min, V t_max) {
    using namespace torus_detail;
    using S = simd::scalar_t<V>;
    using M = mask_t<V>;
    const V inf = inf_v<V>();
    const V zero(0);
    TorusPieces<V> tp;
    if (!torus_pieces(o, d, minor, t_min, t_max, tp)) return inf;
    M valid = tp.valid;
    const Vec3T<V>& p0 = tp.p0;
    const Vec3T<V>& D = tp.D;
    const V& r2 = tp.r2;
    const V* pts = tp.pts;
    const V* fpts = tp.fpts;
    const M* neg = tp.neg;
    const V tc = tp.tc, len = tp.len;

    // 5. First monotone piece with a sign change of F, then solve it.
    auto ffun = [&](const V& s, V& f, V& df) { torus_f(p0, D, r2, s, f, df); };
    V a = zero, bb = zero, fa = zero, fb = zero;
    M neg_a = neg[0];
    M found = neg[0] & !neg[0];  // all false
    for (int i = 3; i >= 0; --i) {
        const M change = simd::mask_xor(neg[i], neg[i + 1]);
        a = simd::select(change, pts[i], a);
        bb = simd::select(change, pts[i + 1], bb);
        fa = simd::select(change, fpts[i], fa);
        fb = simd::select(change, fpts[i + 1], fb);
        neg_a = (change & neg[i]) | ((!change) & neg_a);
        found = found | change;
    }
    valid = valid & found;
    if (!simd::any(valid)) return inf;
    V ra[1] = {a}, rb[1] = {bb}, s_hit[1];
    const V rstart[1] = {false_position(a, bb, fa, fb, valid)};
    const M rneg[1] = {neg_a}, ractive[1] = {valid};
    bracket_solve(ra, rb, rneg, ractive, rstart, kRootTol<S>, ffun, kRootIters, s_hit);
    const V t = (s_hit[0] + tc) / len;
    const M hit = valid & (t > t_min) & (t < t_max);
    return simd::select(hit, t, inf);
}

/// The torus as a solid for CSG (minor <= 1: the tube's inside, where F < 0) over the whole
/// line o + t d (every t): its at most two spans, in order, each [+inf, -inf] where there is
/// none. Every sign change of F on the monotone pieces is a crossing, solved as torus_hit_t
/// solves its first (the same bracket, start and tolerance); they alternate in and out,
/// starting in, as the pieces' outer ends lie outside the torus. An odd count (rounding at a
/// grazing line) leaves the last span open: empty.
template <class V>
std::array<SpanT<V>, 2> torus_spans(const Vec3T<V>& o, const Vec3T<V>& d, V minor) {
    using namespace torus_detail;
    using S = simd::scalar_t<V>;
    using M = mask_t<V>;
    const V inf = inf_v<V>();
    std::array<SpanT<V>, 2> out{{{inf, -inf}, {inf, -inf}}};
    TorusPieces<V> tp;
    if (!torus_pieces(o, d, minor, -inf, inf, tp)) return out;
    V a[4], b[4], start[4], root[4];
    M neg_a[4], change[4];
    M any_change = tp.valid & !tp.valid;
    for (int i = 0; i < 4; ++i) {
        change[i] = tp.valid & simd::mask_xor(tp.neg[i], tp.neg[i + 1]);
        any_change = any_change | change[i];
        a[i] = tp.pts[i];
        b[i] = tp.pts[i + 1];
        neg_a[i] = tp.neg[i];
        start[i] = false_position(tp.pts[i], tp.pts[i + 1], tp.fpts[i], tp.fpts[i + 1], change[i]);
    }
    if (!simd::any(any_change)) return out;
    auto ffun = [&](const V& s, V& f, V& df) { torus_f(tp.p0, tp.D, tp.r2, s, f, df); };
    bracket_solve(a, b, neg_a, change, start, kRootTol<S>, ffun, kRootIters, root);
    // The k-th crossing of a lane is end k: enter, exit, enter, exit.
    V ends[4] = {inf, -inf, inf, -inf};
    V count(0);
    for (int i = 0; i < 4; ++i) {
        const V t = (root[i] + tp.tc) / tp.len;
        for (int k = 0; k < 4; ++k) ends[k] = simd::select(change[i] & (count == V(S(k))), t, ends[k]);
        count = count + simd::select(change[i], V(1), V(0));
    }
    out[0] = {ends[0], ends[1]};
    out[1] = {ends[2], ends[3]};
    return out;
}

/// Outward normal (not necessarily unit length) at a point p on (or very near) the torus
/// surface: p minus the nearest point of the tube's centre circle. For the spindle torus
/// (r > 1) the inner "lemon" surface belongs to the tube centred on the opposite side of the
/// ring, and the normal points away from that circle.
template <class V>
Vec3T<V> torus_normal(const Vec3T<V>& p, V minor) {
    const V zero(0), one(1);
    const V rho2 = p.x * p.x + p.z * p.z;
    const V rho = simd::sqrt(rho2);
    const auto has_rho = rho > zero;
    const V inv_rho = one / simd::select(has_rho, rho, one);
    const V ux = simd::select(has_rho, p.x * inv_rho, zero);
    const V uz = simd::select(has_rho, p.z * inv_rho, zero);
    const V yr = p.y * p.y - minor * minor;
    const V g1 = (rho - one) * (rho - one) + yr;
    const V g2 = (rho + one) * (rho + one) + yr;
    // Near circle (ring point on p's side) unless p lies on the opposite tube's surface.
    const V sgn = simd::select(simd::abs(g2) < simd::abs(g1), V(-1), one);
    return {p.x - sgn * ux, p.y, p.z - sgn * uz};
}

/// The torus as the engines see it (shapes/shape_traits.h). Its quartic is solved in double
/// lanes in both engines.
struct TorusMath {
    static constexpr ShapeKind kind = ShapeKind::Torus;
    static constexpr std::string_view name = "torus";
    static constexpr ShapeParam param{"minor", 0.25};  ///< the tube radius
    using Compute = double;
    /// As a CSG solid (minor <= 1) a line meets it in up to two spans (torus_spans).
    static constexpr int kCsgSpans = 2;
    /// The ring's box: |x|, |z| <= 1 + minor, |y| <= minor.
    static constexpr CanonicalBounds bounds(double minor) {
        return {CanonicalBounds::Form::Box, {-1 - minor, -minor, -1 - minor}, {1 + minor, minor, 1 + minor}};
    }
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V minor, V t_min, V t_max) {
        return torus_hit_t(o, d, minor, t_min, t_max);
    }
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V minor) { return torus_normal(p, minor); }
    /// The two angles: u = 0.5 + atan2(x, z) / (2 pi) around the ring, v = 0.5 +
    /// atan2(y, rho - 1) / (2 pi) around the tube (rho = sqrt(x^2 + z^2); v = 0.5 on the outer
    /// equator, 0.75 on top of the tube, 0 and 1 on the inner equator).
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*minor*/) {
        using namespace simd;
        const V rho = sqrt(p.x * p.x + p.z * p.z);
        return {uv_angle(p.x, p.z), uv_angle(p.y, rho - V(1))};
    }
    /// The tube's rate 1 / (2 pi r), or the ring's 1 / (2 pi) when the tube is thicker.
    template <class V>
    static V uv_density(V minor) {
        using namespace simd;
        return V(0.15915494309189535) / min(minor, V(1));
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
