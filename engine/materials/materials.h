#pragma once
// The registry of material properties. Each property declares itself once, as a small struct
// (key, kind of value, range, its field with the default: materials/material_property.h);
// MaterialProperties below lists them, and `Material` (the scene's material record), its
// equality and hash, and the scene reader's material keys, their conversions and checks and
// the key list of its messages (scene/scene_keys.h) come from that list. The shading term of
// a property is written where it is used (render/shading.h, render/texture.h). Adding a
// property: its struct, one line here (docs/architecture.md, "Adding a material property").
#include <cstddef>
#include <functional>
#include <string_view>

#include "materials/emission_property.h"
#include "materials/fresnel_property.h"
#include "materials/handout_properties.h"
#include "materials/material_property.h"
#include "materials/surface_pattern_properties.h"

namespace streamrt {

template <class... P>
struct PropertyList {
    static_assert((MaterialPropertyDefinition<P> && ...),
                  "a material property declares info and field (materials/material_property.h)");
    static constexpr std::size_t size = sizeof...(P);
    /// Every property's fields: the record derives from this.
    struct Fields : P... {};
    /// Calls f(P{}) for every property, in order.
    template <class F>
    static constexpr void for_each(F&& f) { (f(P{}), ...); }
    /// Calls f(P{}) for the property whose key is `key`; false when there is none.
    template <class F>
    static constexpr bool visit_key(std::string_view key, F&& f) {
        return ((P::info.key == key ? (f(P{}), true) : false) || ...);
    }
    static constexpr bool distinct_keys() {
        const std::string_view keys[] = {P::info.key...};
        for (std::size_t i = 0; i < size; ++i)
            for (std::size_t j = 0; j < i; ++j)
                if (keys[i] == keys[j]) return false;
        return true;
    }
};

namespace property {
/// THE registration list: every material property, in the order messages list their keys.
using Registered =
    PropertyList<Ambi, Diff, Spec, Shininess, Refl, Trans, Ior, Checker, Cell, Fresnel, Texture, UvScale, VertexColors,
                 Emission>;
}  // namespace property
using MaterialProperties = property::Registered;
static_assert(MaterialProperties::distinct_keys(), "two material properties share a key");

/// A material's optical parameters: the fields of every registered property (`m.refl`,
/// `m.checker_color`, ...). The colour is not here: it is the object's own (Object::color), so
/// that scenes whose objects differ only by colour share one material record.
struct Material : MaterialProperties::Fields {
    /// Field by field, through the registry (a property's `given` flag included).
    friend bool operator==(const Material& a, const Material& b) {
        bool equal = true;
        MaterialProperties::for_each([&](auto p) {
            using P = decltype(p);
            equal = equal && a.*P::field == b.*P::field;
            if constexpr (has_given_flag<P>()) equal = equal && a.*P::given == b.*P::given;
        });
        return equal;
    }
};

/// Hash of a material's fields, for deduplication (equal materials hash alike: values are
/// hashed as doubles, +0 and -0 alike through +0.0).
struct MaterialHash {
    std::size_t operator()(const Material& m) const {
        std::size_t h = 0;
        const auto mix = [&h](double v) { h = h * 0x9E3779B97F4A7C15ull ^ std::hash<double>{}(v + 0.0); };
        MaterialProperties::for_each([&](auto p) {
            using P = decltype(p);
            const auto& v = m.*P::field;
            if constexpr (P::info.kind == ValueKind::Colour) mix(v.x), mix(v.y), mix(v.z);
            else mix(double(v));
            if constexpr (has_given_flag<P>()) mix(double(m.*P::given));
        });
        return h;
    }
};

}  // namespace streamrt
