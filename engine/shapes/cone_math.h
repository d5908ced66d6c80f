#pragma once
// Canonical cone: base radius 1 at y = -1, apex at y = +1, base capped.
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "shapes/shape_traits.h"
#include "shapes/solid_span.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct ConeMath {
    static constexpr ShapeKind kind = ShapeKind::Cone;
    static constexpr std::string_view name = "cone";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    static constexpr CanonicalBounds bounds(double /*param*/) {
        return {CanonicalBounds::Form::Box, {-1, -1, -1}, {1, 1, 1}};
    }
    /// Side: x^2 + z^2 = (k (1 - y))^2 with k = 1/2, for y in [-1, 1]. A ray parallel to a
    /// generator has a = 0: solve_quadratic's c/q is then the single linear root.
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/, V t_min, V t_max) {
        using namespace simd;
        const V k2(0.25);
        // b^2 - a c cancels badly when the origin is far away (b^2 ~ |o|^2 |d|^2 while the
        // discriminant is O(|d|^2)): float then kept 3 digits at 11 units and primary hits
        // landed past the surface (shadow acne). Solving from the ray's closest approach to
        // the canonical origin keeps every term O(1); t = t_shift + s.
        const V t_shift = -dot(o, d) / dot(d, d);
        const Vec3T<V> os = o + d * t_shift;
        const V w = V(1) - os.y;  // height below the apex
        const V a = d.x * d.x + d.z * d.z - k2 * d.y * d.y;
        const V b = os.x * d.x + os.z * d.z + k2 * w * d.y;
        const V c = os.x * os.x + os.z * os.z - k2 * w * w;
        const auto r = solve_quadratic(a, b, c, b * b - a * c);
        V best = t_max;
        for (const V& s : {r.t0, r.t1}) {
            const V y = os.y + d.y * s;
            best = keep_closest(best, t_shift + s, r.valid && y >= V(-1) && y <= V(1), t_min);
        }
        best = keep_cap(best, o, d, V(-1), t_min);  // the base
        return miss_if_unchanged(best, t_max);
    }
    /// A convex closed solid: its inside along a line lies between hit_t's two ends (solid_span.h).
    static constexpr bool kConvexSolid = true;
    /// Gradient of the side, (x, k^2 (1 - y), z); the base cap below; +y at the apex itself.
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const V rho = sqrt(p.x * p.x + p.z * p.z);
        // Signed distances: to the cap plane, and (scaled by 1/sqrt(1 + k^2)) to the side.
        const V cap_dist = V(-1) - p.y;
        const V side_dist = (rho - V(0.5) * (V(1) - p.y)) * V(0.894427190999916);
        const auto on_cap = cap_dist > side_dist;
        const V sy = V(0.25) * (V(1) - p.y);
        const auto at_apex = (p.x * p.x + p.z * p.z + sy * sy) == V(0);
        return {select(on_cap || at_apex, V(0), p.x),
                select(on_cap, V(-1), select(at_apex, V(1), sy)),
                select(on_cap || at_apex, V(0), p.z)};
    }
    /// Side: angle and height, (0.5 + atan2(x, z) / (2 pi), (y + 1) / 2); the base (chosen as
    /// the normal is): planar, ((x + 1) / 2, (z + 1) / 2).
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const V rho = sqrt(p.x * p.x + p.z * p.z);
        const auto on_cap = (V(-1) - p.y) > (rho - V(0.5) * (V(1) - p.y)) * V(0.894427190999916);
        const UvT<V> cap = uv_square(p.x, p.z);
        return {select(on_cap, cap.u, uv_angle(p.x, p.z)), select(on_cap, cap.v, (p.y + V(1)) * V(0.5))};
    }
    template <class V>
    static V uv_density(V /*param*/) { return V(0.5); }
};

STREAMRT_ISA_END
}  // namespace streamrt
