#pragma once
// Canonical cylinder: radius 1 around the y axis, y in [-1,1], both ends capped.
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "shapes/shape_traits.h"
#include "shapes/solid_span.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct CylinderMath {
    static constexpr ShapeKind kind = ShapeKind::Cylinder;
    static constexpr std::string_view name = "cylinder";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    static constexpr CanonicalBounds bounds(double /*param*/) {
        return {CanonicalBounds::Form::Box, {-1, -1, -1}, {1, 1, 1}};
    }
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/, V t_min, V t_max) {
        using namespace simd;
        // Side: (ox + t dx)^2 + (oz + t dz)^2 = 1. A ray along the axis has a = 0, so q/a is
        // inf and c/q is NaN (0 / 0) or a root outside |y| <= 1: no side hit, as it should.
        const V a = d.x * d.x + d.z * d.z;
        const V b = o.x * d.x + o.z * d.z;
        const V c = o.x * o.x + o.z * o.z - V(1);
        const V t_mid = -b / a;
        const V px = o.x + d.x * t_mid, pz = o.z + d.z * t_mid;
        const V disc = a * (V(1) - (px * px + pz * pz));
        const auto r = solve_quadratic(a, b, c, disc);
        V best = t_max;
        best = keep_closest(best, r.t0, r.valid && abs(o.y + d.y * r.t0) <= V(1), t_min);
        best = keep_closest(best, r.t1, r.valid && abs(o.y + d.y * r.t1) <= V(1), t_min);
        best = keep_cap(best, o, d, V(-1), t_min);  // caps y = -1 and y = +1
        best = keep_cap(best, o, d, V(1), t_min);
        return miss_if_unchanged(best, t_max);
    }
    /// A convex closed solid: its inside along a line lies between hit_t's two ends (solid_span.h).
    static constexpr bool kConvexSolid = true;
    /// Cap or side, whichever the point is closer to being outside of.
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const V rho = sqrt(p.x * p.x + p.z * p.z);
        const auto on_cap = (abs(p.y) - V(1)) > (rho - V(1));
        return {select(on_cap, V(0), p.x), select(on_cap, sign_of(p.y), V(0)),
                select(on_cap, V(0), p.z)};
    }
    /// Side: angle and height, (0.5 + atan2(x, z) / (2 pi), (y + 1) / 2); caps (chosen as the
    /// normal is): planar, ((x + 1) / 2, (z + 1) / 2).
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const V rho = sqrt(p.x * p.x + p.z * p.z);
        const auto on_cap = (abs(p.y) - V(1)) > (rho - V(1));
        const UvT<V> cap = uv_square(p.x, p.z);
        return {select(on_cap, cap.u, uv_angle(p.x, p.z)), select(on_cap, cap.v, (p.y + V(1)) * V(0.5))};
    }
    template <class V>
    static V uv_density(V /*param*/) { return V(0.5); }
};

STREAMRT_ISA_END
}  // namespace streamrt
