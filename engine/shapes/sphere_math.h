#pragma once
// Canonical sphere: unit radius, centred at the origin.
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "shapes/shape_traits.h"
#include "shapes/solid_span.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct SphereMath {
    static constexpr ShapeKind kind = ShapeKind::Sphere;
    static constexpr std::string_view name = "sphere";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    static constexpr CanonicalBounds bounds(double /*param*/) {
        return {CanonicalBounds::Form::UnitBall, {-1, -1, -1}, {1, 1, 1}};
    }
    /// The two t with |o + t d| = 1 (unordered; `valid` false where the line misses).
    template <class V>
    static QuadraticRoots<V> roots(const Vec3T<V>& o, const Vec3T<V>& d) {
        const V a = dot(d, d);
        const V b = dot(o, d);
        const V c = dot(o, o) - V(1);
        // b^2 - a c written about the closest-approach point (Hearn & Baker; Ray Tracing Gems
        // ch. 7): a (1 - |perp|^2) loses nothing when the ray passes far from the centre.
        const V t_mid = -b / a;
        const Vec3T<V> perp = o + d * t_mid;
        const V disc = a * (V(1) - dot(perp, perp));
        return solve_quadratic(a, b, c, disc);
    }
    /// Nearest t in (t_min, t_max) with |o + t d| = 1, or +inf. d need not be unit length.
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/, V t_min, V t_max) {
        const auto r = roots(o, d);
        V best = t_max;
        best = keep_closest(best, r.t0, r.valid, t_min);
        best = keep_closest(best, r.t1, r.valid, t_min);
        return miss_if_unchanged(best, t_max);
    }
    /// A convex closed solid: its inside along a line lies between hit_t's two ends (solid_span.h).
    static constexpr bool kConvexSolid = true;
    /// Those two ends from one solve: run backwards (d -> -d) the line gives b, t_mid and q
    /// negated exactly and the same discriminant, so its roots are these roots negated; taking
    /// them as hit_t takes them gives convex_span's bits at half its cost (a CSG test checks).
    template <class V>
    static SpanT<V> span(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/) {
        const auto r = roots(o, d);
        const V inf = infinity_v<V>();
        const V ahead = keep_closest(keep_closest(inf, r.t0, r.valid, -inf), r.t1, r.valid, -inf);
        const V behind = keep_closest(keep_closest(inf, -r.t0, r.valid, -inf), -r.t1, r.valid, -inf);
        return {miss_if_unchanged(ahead, inf), -miss_if_unchanged(behind, inf)};
    }
    /// False only where the ray's line surely misses the unit sphere; a packet kernel skips
    /// hit_t (a division, a square root and two more divisions) when no lane may hit, and where
    /// any lane may, hit_t decides every lane as before, so the answers keep their bits.
    /// The test is hit_t's closest-approach discriminant without its divisions: with
    /// w = a o - b d (a times the closest point), a^2 - |w|^2 has the sign of b^2 - a c
    /// without its cancellation far from the sphere. Its float error, with the error of
    /// hit_t's own discriminant, stays under about 24 eps a |w| |o| + 3 eps |w|^2 + 7 eps a^2
    /// (eps = 2^-24: the closest point carries an error of a few eps |o|); the margin is
    /// 2^-17 = 128 eps times the sum. At 1000 radii from the centre, lines passing more than
    /// about 1.004 radii away are rejected.
    template <class V>
    static auto may_hit(const Vec3T<V>& o, const Vec3T<V>& d) {
        const V a = dot(d, d);
        const V b = dot(o, d);
        const Vec3T<V> w = o * a - d * b;
        const V ww = dot(w, w), aa = a * a;
        // a^2 - |w|^2 >= -k (a |w| |o| + |w|^2 + a^2), k = 2^-17, squared to spare a root.
        const V k(0.00000762939453125f);
        const V slack = aa - ww + k * (ww + aa);
        return slack >= V(0) || slack * slack <= k * k * (aa * ww * dot(o, o));
    }
    /// Outward normal (not unit) at a surface point.
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V /*param*/) { return p; }
    /// Longitude and latitude: u = 0.5 + atan2(x, z) / (2 pi), v = 0.5 + asin(y / |p|) / pi
    /// (v = 0 at the south pole y = -1, 1 at the north pole), the latitude computed as
    /// atan2(y, sqrt(x^2 + z^2)) (simd/stable_math.h, the same bits at every ISA level).
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const V latitude = stable_atan2(p.y, sqrt(p.x * p.x + p.z * p.z));
        return {uv_angle(p.x, p.z), V(0.5) + latitude * V(0.3183098861837907)};
    }
    /// dv/ds = 1 / pi along a meridian (du/ds = 1 / (2 pi) at the equator).
    template <class V>
    static V uv_density(V /*param*/) { return V(0.3183098861837907); }
};

STREAMRT_ISA_END
}  // namespace streamrt
