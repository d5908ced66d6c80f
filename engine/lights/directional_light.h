#pragma once
// The handout's directional light: parallel light travelling along `dir`, from infinitely far.
#include "lights/light_traits.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct DirectionalLight {
    static constexpr LightKind kind = LightKind::Directional;
    static constexpr std::string_view name = "directional";
    static constexpr bool area = false;
    static constexpr std::string_view keys[] = {"dir", "color", "falloff", "name"};
    static constexpr std::string_view required[] = {"dir"};
    static LightProblem check(const Light&) { return {}; }
    /// No falloff: the light is at infinity (the caller skips inverse_square for it).
    template <class V, class T>
    static ShapedSample<V> sample(const LightT<T>& l, const Vec3T<V>& p, const V&, const V&) {
        ShapedSample<V> r;
        r.ls = sample_light(l, p);
        r.at = p + r.ls.w;
        r.scale = V(1);
        return r;
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
