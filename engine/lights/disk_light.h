#pragma once
// A disk area light of radius `radius` centred on `pos`, facing `dir`: it lights the side dir
// points to (docs/scene-format.md, "Area lights and soft shadows"). Registered with one line in
// lights/lights.h and one LightKind; the reader, both engines and the docs' key list take it
// from there.
#include "lights/light_traits.h"
#include "simd/stable_math.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct DiskLight {
    static constexpr LightKind kind = LightKind::Disk;
    static constexpr std::string_view name = "disk";
    static constexpr bool area = true;
    static constexpr std::string_view keys[] = {"pos", "dir", "radius", "color", "samples", "falloff", "name"};
    static constexpr std::string_view required[] = {"pos", "dir", "radius"};
    static LightProblem check(const Light&) { return {}; }
    /// A point uniform on the disk (radius R sqrt(u1), angle u2 turns: uniform in area),
    /// weighted by the emitter cosine like the rect light.
    template <class V, class T>
    static ShapedSample<V> sample(const LightT<T>& l, const Vec3T<V>& p, const V& u1, const V& u2) {
        using namespace simd;
        Vec3T<V> b1, b2;
        orthonormal_basis(splat<V>(l.dir), b1, b2);
        V cos_phi, sin_phi;
        simd::cos_sin_of_turn(u2, cos_phi, sin_phi);
        const V rho = V(l.radius) * sqrt(u1);
        const Vec3T<V> at = splat<V>(l.pos) + b1 * (rho * cos_phi) + b2 * (rho * sin_phi);
        return one_sided_emitter_sample(at, p, l.dir);
    }
};

STREAMRT_ISA_END
}  // namespace streamrt
