#pragma once
// A light as the scene holds it (Light, double) and as the engines shade with it (LightT, in
// their precision), and what one sample of a light gives a shaded point. The kinds
// themselves, each in its own file, are registered in lights/lights.h.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>

#include "core/enum_names.h"
#include "core/vec_lanes.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {

/// The light kinds, in the order of their registration (lights/lights.h, LightKinds), which
/// checks at compile time that the two agree. Sphere, Rect and Disk are area lights.
enum class LightKind : std::uint8_t { Point, Spot, Directional, Sphere, Rect, Disk };

/// How a light's colour falls with the distance d to it: none (the handout's) or 1 / d^2.
enum class Falloff : std::uint8_t { None, InverseSquare };
inline constexpr EnumName<Falloff> kFalloffNames[] = {{Falloff::None, "none"}, {Falloff::InverseSquare, "inverse_square"}};

/// The scene's light: every kind's parameters (docs/scene-format.md, "Lights"); each kind reads
/// the ones its keys set.
struct Light {
    LightKind kind = LightKind::Point;
    glm::dvec3 pos{0.0, 0.0, 0.0};   ///< point, spot, sphere and disk centre, rect corner
    glm::dvec3 dir{0.0, -1.0, 0.0};  ///< normalised; spot axis, directional travel direction, disk's lit side
    glm::dvec3 color{1.0, 1.0, 1.0};
    double angle = 30.0;  ///< spot: half-angle of the cone, degrees
    // Area lights, falloff and soft spot edges (defaults: the handout's lights).
    double radius = 0.0;                  ///< sphere, disk
    glm::dvec3 u{0.0, 0.0, 0.0}, v{0.0, 0.0, 0.0};  ///< rect: edges from the corner pos; lights the u x v side
    int samples = 1;                      ///< area lights: shadow rays per shaded point
    Falloff falloff = Falloff::None;
    double soft = 0.0;                    ///< spot: width of the smooth edge inside the cone, degrees

    /// An area light (its kind's `area`, lights/lights.h): `samples` shadow rays per point.
    bool is_area() const;
    /// Lit by shade_hit's sampled path (render/shading.h): an area light, a falloff or a soft edge.
    bool shaped() const { return is_area() || falloff != Falloff::None || soft > 0.0; }
};

/// A light in the engine's precision.
template <class T>
struct LightT {
    LightKind kind;
    Vec3T<T> pos;
    Vec3T<T> dir;  ///< unit: spot axis, directional travel direction, disk's lit side
    ColorT<T> color;
    T cos_angle;   ///< spot: cosine of the half-angle
    // Area lights, falloff and soft edges: a light with `shaped` false (the handout's) takes
    // shade_hit's original path and reads none of these.
    bool shaped = false;          ///< Light::shaped(): lit by shade_shaped_light
    bool inverse_square = false;  ///< falloff=inverse_square
    bool soft = false;            ///< spot with a soft edge
    T cos_inner = T(1);           ///< soft spot: cosine of angle - soft (full light inside)
    T radius = T(0);              ///< sphere, disk
    Vec3T<T> u{}, v{};            ///< rect: edges from the corner pos
    Vec3T<T> normal{};            ///< rect: unit u x v, the lit side
    bool area = false;            ///< Light::is_area(): samples on a lattice
    int samples = 1;              ///< area lights: samples per shaded point
    int columns = 1;              ///< their stratification lattice: columns x (samples / columns)

    static LightT from(const Light& l) {
        constexpr double kDeg = 3.14159265358979323846 / 180.0;
        LightT r{l.kind, {T(l.pos.x), T(l.pos.y), T(l.pos.z)},
                 {T(l.dir.x), T(l.dir.y), T(l.dir.z)}, {T(l.color.x), T(l.color.y), T(l.color.z)},
                 T(std::cos(l.angle * kDeg))};
        r.shaped = l.shaped();
        r.inverse_square = l.falloff == Falloff::InverseSquare;
        r.soft = l.kind == LightKind::Spot && l.soft > 0.0;
        r.cos_inner = T(std::cos((l.angle - l.soft) * kDeg));
        r.radius = T(l.radius);
        r.u = {T(l.u.x), T(l.u.y), T(l.u.z)};
        r.v = {T(l.v.x), T(l.v.y), T(l.v.z)};
        const glm::dvec3 n = glm::cross(l.u, l.v);
        const double len = glm::length(n);
        if (len > 0.0) r.normal = {T(n.x / len), T(n.y / len), T(n.z / len)};
        r.area = l.is_area();
        r.samples = r.area ? std::max(1, l.samples) : 1;
        r.columns = r.area ? area_light_columns(r.samples) : 1;
        return r;
    }
    /// Columns of the lattice of n samples: as square as possible, columns dividing n.
    static int area_light_columns(int n) {
        int cols = int(std::ceil(std::sqrt(double(n))));
        while (n % cols != 0) ++cols;
        return cols;
    }
};

/// Where a light is seen from p: unit direction w towards it, the shadow-ray segment
/// (p + t to_light, t in (0, t_max)) and whether p is inside the light's reach (spot cone).
template <class V>
struct LightSample {
    Vec3T<V> w;         ///< unit, towards the light
    Vec3T<V> to_light;  ///< shadow-ray direction: light - p for lights at a point, w otherwise
    V t_max;            ///< 1 for lights at a point, +inf for directional
    MaskOf<V> reaches;  ///< false outside a spot's cone
};

/// One sample of a shaped light seen from p: the point-light term's direction and reach
/// (ls), the sample point `at` (lights at a point) and what the term is multiplied by.
template <class V>
struct ShapedSample {
    LightSample<V> ls;
    Vec3T<V> at;
    V scale;
};

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// The handout's light at a point: towards pos, inside a spot's cone; or along -dir
/// (directional). The unshaped path of shade_hit and the point-like kinds' samples.
template <class V, class T>
inline LightSample<V> sample_light(const LightT<T>& l, const Vec3T<V>& p) {
    LightSample<V> s;
    if (l.kind == LightKind::Directional) {
        s.w = splat<V>(-l.dir);
        s.to_light = s.w;
        s.t_max = V(std::numeric_limits<T>::infinity());
        s.reaches = V(0) == V(0);
        return s;
    }
    s.to_light = splat<V>(l.pos) - p;
    s.w = normalize(s.to_light);
    s.t_max = V(1);
    if (l.kind == LightKind::Point) s.reaches = V(0) == V(0);
    else s.reaches = dot(-s.w, splat<V>(l.dir)) >= V(l.cos_angle);
    return s;
}

/// A sample of an emitter that lights one side: the point `at` seen from p, weighted by the
/// emitter's cosine towards p (zero behind it). Rect and disk lights share it.
template <class V, class T>
inline ShapedSample<V> one_sided_emitter_sample(const Vec3T<V>& at, const Vec3T<V>& p, const Vec3T<T>& lit_side) {
    using namespace simd;
    ShapedSample<V> r;
    r.at = at;
    r.ls.to_light = at - p;
    r.ls.w = normalize(r.ls.to_light);
    r.ls.t_max = V(1);
    const V emit = -dot(r.ls.w, splat<V>(lit_side));
    r.ls.reaches = emit > V(0);
    r.scale = max(emit, V(0));
    return r;
}

/// An orthonormal pair (b1, b2) completing the unit vector a (Duff et al. 2017, branch-free).
template <class V>
inline void orthonormal_basis(const Vec3T<V>& a, Vec3T<V>& b1, Vec3T<V>& b2) {
    using namespace simd;
    const V sg = sign_of(a.z);
    const V k = V(-1) / (sg + a.z);
    const V b = a.x * a.y * k;
    b1 = {V(1) + sg * a.x * a.x * k, sg * b, -sg * a.x};
    b2 = {b, sg + a.y * a.y * k, -a.y};
}

STREAMRT_ISA_END
}  // namespace streamrt
