#pragma once
// The handout's local lighting by degree, reflection, refraction and ray-origin offsets,
// written once for T = double (recursive baseline) and T = float (stream engine).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/vec3.h"
#include "scene/scene.h"

namespace streamrt {

template <class T>
using ColorT = Vec3T<T>;

template <class T>
struct MaterialT {
    ColorT<T> color, checker_color;
    T ambi, diff, spec, shininess, refl, trans, ior, inv_cell;
    bool checker;

    static MaterialT from(const Material& m) {
        return {{T(m.color.x), T(m.color.y), T(m.color.z)},
                {T(m.checker_color.x), T(m.checker_color.y), T(m.checker_color.z)},
                T(m.ambi), T(m.diff), T(m.spec), T(m.shininess), T(m.refl), T(m.trans),
                T(m.ior), T(1.0 / m.cell), m.checker};
    }
};

template <class T>
struct LightT {
    LightKind kind;
    Vec3T<T> pos;
    Vec3T<T> dir;  ///< unit: spot axis or directional travel direction
    ColorT<T> color;
    T cos_angle;   ///< spot: cosine of the half-angle

    static LightT from(const Light& l) {
        return {l.kind, {T(l.pos.x), T(l.pos.y), T(l.pos.z)},
                {T(l.dir.x), T(l.dir.y), T(l.dir.z)}, {T(l.color.x), T(l.color.y), T(l.color.z)},
                T(std::cos(l.angle * 3.14159265358979323846 / 180.0))};
    }
};

/// Checker cells of side `cell` centred on multiples of cell: y = 0 floors sit mid-cell, so
/// float noise in a coordinate cannot flip the parity there.
template <class T>
inline ColorT<T> surface_color(const MaterialT<T>& m, const Vec3T<T>& p) {
    if (!m.checker) return m.color;
    const auto cell = [&](T v) { return static_cast<std::int64_t>(std::floor(v * m.inv_cell + T(0.5))); };
    const std::int64_t parity = (cell(p.x) + cell(p.y) + cell(p.z)) & 1;
    return parity ? m.checker_color : m.color;
}

/// Where a light is seen from p: unit direction w towards it, the shadow-ray segment
/// (p + t (to_light), t in (0, t_max)) and whether p is lit at all (spot cone).
template <class T>
struct LightSample {
    Vec3T<T> w;         ///< unit, towards the light
    Vec3T<T> to_light;  ///< shadow-ray direction: light - p for lights at a point, w otherwise
    T t_max;            ///< 1 for lights at a point (just short of it), +inf for directional
    bool reaches;       ///< false outside a spot's cone
};

template <class T>
inline LightSample<T> sample_light(const LightT<T>& l, const Vec3T<T>& p) {
    LightSample<T> s;
    if (l.kind == LightKind::Directional) {
        s.w = -l.dir;
        s.to_light = s.w;
        s.t_max = std::numeric_limits<T>::infinity();
        s.reaches = true;
        return s;
    }
    s.to_light = l.pos - p;
    s.w = normalize(s.to_light);
    s.t_max = T(1);
    s.reaches = l.kind == LightKind::Point || dot(-s.w, l.dir) >= l.cos_angle;
    return s;
}

/// Direct light from one light at degree >= 1 (visibility is the caller's business):
/// degree 1: (N.w) Col with the light taken as white; degree >= 2: light colour x
/// (diff (N.w) Col + spec (R.V)^shininess).  n faces the viewer; view is the ray direction.
template <class T>
inline ColorT<T> direct_light(int degree, const MaterialT<T>& m, const ColorT<T>& base,
                              const Vec3T<T>& n, const Vec3T<T>& view, const LightT<T>& l,
                              const LightSample<T>& s) {
    const T ndotw = dot(n, s.w);
    if (!s.reaches || !(ndotw > T(0))) return {T(0), T(0), T(0)};
    if (degree == 1) return base * ndotw;
    ColorT<T> c = base * (m.diff * ndotw);
    if (m.spec > T(0)) {
        const Vec3T<T> r = n * (T(2) * ndotw) - s.w;  // w mirrored about n
        const T rv = -dot(r, view);
        if (rv > T(0)) {
            const T h = m.spec * std::pow(rv, m.shininess);
            c = c + ColorT<T>{h, h, h};
        }
    }
    return mul(c, l.color);
}

/// The part of the colour that needs no light: degree 0 the flat colour, degree 1
/// alpha Col, degree >= 2 alpha ambi Col.
template <class T>
inline ColorT<T> ambient_light(int degree, T alpha, const MaterialT<T>& m, const ColorT<T>& base) {
    if (degree == 0) return base;
    if (degree == 1) return base * alpha;
    return base * (alpha * m.ambi);
}

template <class T>
inline Vec3T<T> reflect(const Vec3T<T>& d, const Vec3T<T>& n) {
    return d - n * (T(2) * dot(d, n));
}

/// Snell's law for a unit d at a surface of outward unit normal n and index ior inside.
/// Entering when d.n < 0. On total internal reflection returns the mirror direction.
template <class T>
inline Vec3T<T> refract(const Vec3T<T>& d, const Vec3T<T>& n, T ior, bool* total_internal = nullptr) {
    T cos_i = -dot(d, n);
    Vec3T<T> nn = n;
    T eta = T(1) / ior;
    if (cos_i < T(0)) {  // leaving
        cos_i = -cos_i;
        nn = -n;
        eta = ior;
    }
    const T k = T(1) - eta * eta * (T(1) - cos_i * cos_i);
    if (total_internal) *total_internal = k < T(0);
    if (k < T(0)) return reflect(d, nn);
    return normalize(d * eta + nn * (eta * cos_i - std::sqrt(k)));
}

namespace detail {
template <class T>
struct OffsetTraits;
template <>
struct OffsetTraits<float> {
    using Int = std::int32_t;
    static constexpr float kIntScale = 256.f;        // ulps pushed along the normal
    static constexpr float kFloatScale = 1.f / 65536.f;
};
template <>
struct OffsetTraits<double> {
    using Int = std::int64_t;
    static constexpr double kIntScale = 1048576.0;  // as many ulps, relatively, for double's error
    static constexpr double kFloatScale = 1.0 / 4294967296.0;
};
template <class T>
inline T add_ulps(T v, typename OffsetTraits<T>::Int ulps) {
    typename OffsetTraits<T>::Int bits;
    std::memcpy(&bits, &v, sizeof v);
    bits += v < T(0) ? -ulps : ulps;
    std::memcpy(&v, &bits, sizeof v);
    return v;
}
}  // namespace detail

/// Moves a hit point off its surface along n (the side the new ray leaves on) by an amount
/// proportional to the point's own magnitude, counted in ulps (Waechter & Binder, "A Fast
/// and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6): no
/// scene-dependent epsilon, right at 1e-4 and at 1e6 units. Near the origin, where ulps
/// vanish, a small absolute step.
template <class T>
inline Vec3T<T> offset_ray_origin(const Vec3T<T>& p, const Vec3T<T>& n) {
    using Tr = detail::OffsetTraits<T>;
    using Int = typename Tr::Int;
    constexpr T kOrigin = T(1) / T(32);
    const auto one = [&](T pc, T nc) {
        if (std::fabs(pc) < kOrigin) return pc + Tr::kFloatScale * nc;
        return detail::add_ulps(pc, static_cast<Int>(Tr::kIntScale * nc));
    };
    return {one(p.x, n.x), one(p.y, n.y), one(p.z, n.z)};
}

}  // namespace streamrt
