#pragma once
// A spherical area light of radius `radius` around `pos` (docs/scene-format.md, "Area lights
// and soft shadows").
#include <limits>

#include "lights/light_traits.h"
#include "simd/stable_math.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct SphereLight {
    static constexpr LightKind kind = LightKind::Sphere;
    static constexpr std::string_view name = "sphere";
    static constexpr bool area = true;
    static constexpr std::string_view keys[] = {"pos", "radius", "color", "samples", "falloff", "name"};
    static constexpr std::string_view required[] = {"pos", "radius"};
    static LightProblem check(const Light&) { return {}; }
    /// A direction uniform in the solid angle of the cap of the sphere visible from p (cone
    /// sampling: cos theta uniform in [cos theta_max, 1]), ending on the sphere's near side.
    template <class V, class T>
    static ShapedSample<V> sample(const LightT<T>& l, const Vec3T<V>& p, const V& u1, const V& u2) {
        using namespace simd;
        ShapedSample<V> r;
        const Vec3T<V> c = splat<V>(l.pos) - p;
        const V d2 = dot(c, c);
        const V r2(l.radius * l.radius);
        const V dist = sqrt(d2);
        // At the very centre (dist 0) any axis will do: a = 0 still gives a unit w below.
        const Vec3T<V> a = c * (V(1) / max(dist, V(std::numeric_limits<T>::min())));
        const V cos_max = sqrt(V(1) - min(r2 / d2, V(1)));
        const V cos_t = V(1) - u1 * (V(1) - cos_max);
        const V sin_t = sqrt(max(V(1) - cos_t * cos_t, V(0)));
        V cos_phi, sin_phi;
        simd::cos_sin_of_turn(u2, cos_phi, sin_phi);
        Vec3T<V> b1, b2;
        orthonormal_basis(a, b1, b2);
        const Vec3T<V> w = b1 * (sin_t * cos_phi) + b2 * (sin_t * sin_phi) + a * cos_t;
        // Along w to the sphere: its near side, or its far side from inside the light.
        const V h = sqrt(max(r2 - d2 * sin_t * sin_t, V(0)));
        const V t = select(d2 > r2, dist * cos_t - h, dist * cos_t + h);
        r.at = p + w * t;
        r.ls.w = w;
        r.ls.to_light = w * t;
        r.ls.t_max = V(1);
        r.ls.reaches = t > V(0);
        r.scale = V(1);
        return r;
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
