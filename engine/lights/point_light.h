#pragma once
// The handout's point light: colour from a point, in every direction.
#include "lights/light_traits.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct PointLight {
    static constexpr LightKind kind = LightKind::Point;
    static constexpr std::string_view name = "point";
    static constexpr bool area = false;
    static constexpr std::string_view keys[] = {"pos", "color", "falloff", "name"};
    static constexpr std::string_view required[] = {"pos"};
    static LightProblem check(const Light&) { return {}; }
    template <class V, class T>
    static ShapedSample<V> sample(const LightT<T>& l, const Vec3T<V>& p, const V&, const V&) {
        ShapedSample<V> r;
        r.ls = sample_light(l, p);
        r.at = splat<V>(l.pos);
        r.scale = V(1);
        return r;
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
