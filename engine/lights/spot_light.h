#pragma once
// The handout's spot: a point light inside a cone of half-angle `angle` around `dir`, with an
// optional smooth edge `soft` degrees wide inside the cone.
#include <string>

#include "lights/light_traits.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct SpotLight {
    static constexpr LightKind kind = LightKind::Spot;
    static constexpr std::string_view name = "spot";
    static constexpr bool area = false;
    static constexpr std::string_view keys[] = {"pos", "dir", "angle", "color", "falloff", "soft", "name"};
    static constexpr std::string_view required[] = {"pos", "dir"};
    static LightProblem check(const Light& l) {
        if (l.soft > 0.0 && !(l.soft < l.angle))
            return {"soft", "'soft' must be below the spot's 'angle' (" + fmt_num(l.angle) + ")", true};
        return {};
    }
    /// The soft edge: the smoothstep of the cosine from cos(angle) (0) to cos(angle - soft) (1).
    template <class V, class T>
    static ShapedSample<V> sample(const LightT<T>& l, const Vec3T<V>& p, const V&, const V&) {
        using namespace simd;
        ShapedSample<V> r;
        r.ls = sample_light(l, p);
        r.at = splat<V>(l.pos);
        r.scale = V(1);
        if (l.soft) {
            const V c = dot(-r.ls.w, splat<V>(l.dir));
            const V x = min(max((c - V(l.cos_angle)) / V(l.cos_inner - l.cos_angle), V(0)), V(1));
            r.scale = x * x * (V(3) - V(2) * x);
        }
        return r;
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
