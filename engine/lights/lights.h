#pragma once
// The registry of light kinds. Each kind declares itself once, in its own file (kind,
// scene-format name, area or not, keys, required keys, checks, one sample:
// lights/light_traits.h); LightKinds below lists them, and the reader's keywords, keys and
// checks (scene/parse_statements.cpp), the area-light lattice and both engines' sampled
// lighting (render/shading.h, through visit_light) come from that list. Adding a light kind:
// its file, its LightKind (lights/light.h), one line here (docs/architecture.md, "Adding a
// light kind").
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "lights/directional_light.h"
#include "lights/disk_light.h"
#include "lights/light.h"
#include "lights/point_light.h"
#include "lights/rect_light.h"
#include "lights/sphere_light.h"
#include "lights/spot_light.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// A light kind declares every member with the expected types.
template <class L>
concept LightKindDefinition = requires(const Light& l, const LightT<double>& ld, const Vec3T<double>& p, double u) {
    { L::kind } -> std::convertible_to<LightKind>;
    { L::name } -> std::convertible_to<std::string_view>;
    { L::area } -> std::convertible_to<bool>;
    { L::keys[0] } -> std::convertible_to<std::string_view>;
    { L::required[0] } -> std::convertible_to<std::string_view>;
    { L::check(l) } -> std::same_as<LightProblem>;
    { L::template sample<double>(ld, p, u, u) } -> std::same_as<ShapedSample<double>>;
};

template <class... L>
struct LightList {
    static_assert((LightKindDefinition<L> && ...), "a light kind declares the members of lights/light_traits.h");
    static constexpr std::size_t size = sizeof...(L);
    template <std::size_t I>
    using at = std::tuple_element_t<I, std::tuple<L...>>;
    /// Calls f(L{}) for every kind, in order.
    template <class F>
    static constexpr void for_each(F&& f) { (f(L{}), ...); }
    static constexpr bool in_kind_order() {
        std::size_t i = 0;
        return ((std::size_t(L::kind) == i++) && ...);
    }
};

/// THE registration list: every light kind, in LightKind order.
using LightKinds = LightList<PointLight, SpotLight, DirectionalLight, SphereLight, RectLight, DiskLight>;
static_assert(LightKinds::in_kind_order(), "LightKinds lists the kinds in LightKind order");

/// f(L{}) for the definition of kind k (a switch generated from LightKinds).
template <class F>
inline auto visit_light(LightKind k, F&& f) {
    return [&]<std::size_t... I>(std::index_sequence<I...>) {
        using R = decltype(f(LightKinds::at<0>{}));
        R r{};
        (void)((std::size_t(k) == I ? (r = f(LightKinds::at<I>{}), true) : false) || ...);  // stops at the match
        return r;
    }(std::make_index_sequence<LightKinds::size>{});
}

STREAMRT_ISA_END

inline constexpr int kLightKindCount = int(LightKinds::size);

/// Whether kind k is an area light (its definition's `area`).
constexpr bool light_is_area(LightKind k) {
    bool area = false;
    std::size_t i = 0;
    LightKinds::for_each([&](auto l) { area = area || (i++ == std::size_t(k) && decltype(l)::area); });
    return area;
}
inline bool Light::is_area() const { return light_is_area(kind); }

/// The kind named `name` in the scene format, if any.
inline std::optional<LightKind> light_kind_named(std::string_view name) {
    std::optional<LightKind> found;
    LightKinds::for_each([&](auto l) {
        if (decltype(l)::name == name) found = decltype(l)::kind;
    });
    return found;
}
/// "point, spot, directional, sphere, rect or disk".
inline std::string light_kind_names() {
    std::string s;
    std::size_t i = 0;
    LightKinds::for_each([&](auto l) {
        if (i > 0) s += i + 1 == LightKinds::size ? " or " : ", ";
        s += decltype(l)::name;
        ++i;
    });
    return s;
}

}  // namespace streamrt
