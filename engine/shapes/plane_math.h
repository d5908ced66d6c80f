#pragma once
// Canonical plane: y = 0, normal +y, infinite.
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "shapes/shape_traits.h"
#include "shapes/solid_span.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct PlaneMath {
    static constexpr ShapeKind kind = ShapeKind::Plane;
    static constexpr std::string_view name = "plane";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    /// Unbounded (outside the hierarchy); the y extent 0 says where it lies.
    static constexpr CanonicalBounds bounds(double /*param*/) {
        return {CanonicalBounds::Form::Unbounded, {-kUnboundedExtent, 0, -kUnboundedExtent},
                {kUnboundedExtent, 0, kUnboundedExtent}};
    }
    /// A ray parallel to the plane gives t = +-inf (or NaN when it lies in it): both miss.
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/, V t_min, V t_max) {
        const V t = -o.y / d.y;
        // The other components do not enter t; x - x == 0 is false for NaN and inf, so a
        // poisoned ray misses instead of producing a NaN hit point.
        const V rest = o.x + o.z + d.x + d.z;
        return miss_if_unchanged(keep_closest(t_max, t, rest - rest == V(0), t_min), t_max);
    }
    /// As a solid, the half-space y <= 0 below the plane (its normal points out of it, as in
    /// POV-Ray). A line rising through the plane is inside before the crossing, a falling one
    /// after it; a line parallel to it is inside everywhere (y <= 0) or nowhere.
    template <class V>
    static SpanT<V> inside_span(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/) {
        using namespace simd;
        const V inf = infinity_v<V>();
        const V t = -o.y / d.y;
        const auto rising = d.y > V(0), falling = d.y < V(0), below = o.y <= V(0);
        const V all = select(below, -inf, inf), none = select(below, inf, -inf);
        return {select(rising, -inf, select(falling, t, all)), select(rising, t, select(falling, inf, none))};
    }
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& /*p*/, V /*param*/) { return {V(0), V(1), V(0)}; }
    /// Planar: (u, v) = (x, z), one image per canonical unit (repeated; uvscale= tiles it).
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*param*/) { return {p.x, p.z}; }
    template <class V>
    static V uv_density(V /*param*/) { return V(1.0); }
};

STREAMRT_ISA_END
}  // namespace streamrt
