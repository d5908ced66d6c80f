#pragma once
// A parallelogram area light pos + s u + t v, s, t in [0, 1], lighting the u x v side
// (docs/scene-format.md, "Area lights and soft shadows").
#include <cmath>

#include "lights/light_traits.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct RectLight {
    static constexpr LightKind kind = LightKind::Rect;
    static constexpr std::string_view name = "rect";
    static constexpr bool area = true;
    static constexpr std::string_view keys[] = {"pos", "u", "v", "color", "samples", "falloff", "name"};
    static constexpr std::string_view required[] = {"pos", "u", "v"};
    static LightProblem check(const Light& l) {
        const double area = glm::length(glm::cross(l.u, l.v));
        // Relative to the edges' lengths, so the test does not depend on the scene's unit.
        if (!(area > 1e-12 * glm::length(l.u) * glm::length(l.v)) || !std::isfinite(area))
            return {"v", "light rect: 'u' and 'v' span no area (u x v = 0)"};
        return {};
    }
    /// A point uniform on the parallelogram, weighted by the emitter cosine.
    template <class V, class T>
    static ShapedSample<V> sample(const LightT<T>& l, const Vec3T<V>& p, const V& u1, const V& u2) {
        return one_sided_emitter_sample(splat<V>(l.pos) + splat<V>(l.u) * u1 + splat<V>(l.v) * u2, p, l.normal);
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
