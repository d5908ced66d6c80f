#pragma once
// What a canonical shape declares about itself, in its own math file (shapes/<shape>_math.h),
// and the concept that checks it. shapes/shapes.h registers the shapes and generates from
// them everything the scene reader, the hierarchy and the kernels need per kind.
#include <concepts>
#include <cstdint>
#include <limits>
#include <string_view>
#include <type_traits>

#include <xsimd/xsimd.hpp>

#include "core/vec3.h"
#include "shapes/shape_kind.h"

namespace streamrt {

/// A shape's one number (Object::param, ObjectXf::param): its scene-format key and default.
/// The reader accepts the key on that shape's statements only and requires a finite value
/// > 0. An empty key: the shape has no parameter and param is 0.
struct ShapeParam {
    std::string_view key;
    double default_value = 0.0;
    constexpr bool present() const { return !key.empty(); }
};
inline constexpr ShapeParam kNoShapeParam{};

/// The shape's extent in canonical space, which the hierarchy and the flat kernels' culling
/// boxes take through Md. Never smaller than the shape: a box that misses part of it lets
/// the culling drop real hits.
struct CanonicalBounds {
    enum class Form : std::uint8_t {
        Unbounded,  ///< no finite box (the plane): kept outside the hierarchy, never culled
        Box,        ///< the box [lo, hi]; its image through Md is bounded by Md's 8 corners
        UnitBall,   ///< the unit ball (lo, hi = -+1): the exact box of its affine image
    };
    Form form;
    double lo[3], hi[3];
    constexpr bool bounded() const { return form != Form::Unbounded; }
};

/// Texture coordinates of a surface point (docs/scene-format.md, "Textures and UV mapping"):
/// each shape's uv<V>(p, param) maps its canonical hit point p to (u, v), and its
/// uv_density<V>(param) is how fast (u, v) changes per canonical unit of length along the
/// surface (the larger of the two rates; an approximation where it varies), which the mip
/// level selection uses (render/texture.h).
template <class V>
struct UvT {
    V u, v;
};

inline constexpr double kUnboundedExtent = std::numeric_limits<double>::infinity();

/// Everything the engines need of a canonical shape S, all static:
///   kind            its ShapeKind (also its place in CanonicalShapes)
///   name            its statement keyword in the scene format
///   param           its parameter key and default, or kNoShapeParam
///   bounds(param)   its canonical bounds
///   Compute         the kernels' lane type: float, or double where float is not enough
///   hit_t<V>(o, d, param, t_min, t_max)   nearest t in (t_min, t_max), +inf for a miss
///   normal<V>(p, param)                   outward normal (not unit) at a surface point
///   uv<V>(p, param), uv_density(param)    texture mapping (UvT below)
/// for V = double (baseline), float (scalar shade) and xsimd batches (kernels).
template <class S>
concept CanonicalShape = requires(const Vec3T<double>& pd, double d, const Vec3T<float>& pf, float f,
                                  const Vec3T<xsimd::batch<typename S::Compute>>& pb,
                                  xsimd::batch<typename S::Compute> b) {
    requires std::same_as<std::remove_cv_t<decltype(S::kind)>, ShapeKind>;
    requires std::same_as<std::remove_cv_t<decltype(S::name)>, std::string_view>;
    requires std::same_as<std::remove_cv_t<decltype(S::param)>, ShapeParam>;
    { S::bounds(d) } -> std::same_as<CanonicalBounds>;
    requires std::same_as<typename S::Compute, float> || std::same_as<typename S::Compute, double>;
    { S::template hit_t<double>(pd, pd, d, d, d) } -> std::same_as<double>;
    { S::template hit_t<float>(pf, pf, f, f, f) } -> std::same_as<float>;
    { S::template hit_t<decltype(b)>(pb, pb, b, b, b) } -> std::same_as<decltype(b)>;
    { S::template normal<double>(pd, d) } -> std::same_as<Vec3T<double>>;
    { S::template normal<float>(pf, f) } -> std::same_as<Vec3T<float>>;
    { S::template normal<decltype(b)>(pb, b) } -> std::same_as<Vec3T<decltype(b)>>;
    { S::template uv<double>(pd, d) } -> std::same_as<UvT<double>>;
    { S::template uv<float>(pf, f) } -> std::same_as<UvT<float>>;
    { S::template uv_density<double>(d) } -> std::same_as<double>;
};

}  // namespace streamrt
