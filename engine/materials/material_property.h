#pragma once
// What a material property declares (materials/materials.h lists them): its scene-format key,
// the kind of value it takes (which fixes how the reader converts and checks it, its C++ type,
// and how it is hashed and compared), its range, and the field that holds it, with its
// default as the field's initialiser. A property is a small struct holding that field:
// `Material` derives from every registered property, so the field reads as `m.refl`.
#include <glm/glm.hpp>

#include <concepts>
#include <cstdint>
#include <string_view>
#include <type_traits>

namespace streamrt {

/// How a property's value is written in a scene file. The reader has one checked conversion
/// per kind (scene/scene_keys.h, read_property), each failing at the value's file:line:col.
enum class ValueKind : std::uint8_t {
    Number,  ///< one finite number, within the property's `bound`          (double)
    Colour,  ///< R,G,B: three finite numbers >= 0, at most 3.4e38          (glm::dvec3)
    Flag,    ///< `true` or `false`                                         (bool)
    Image,   ///< a PNG or JPEG file, relative to the statement's file,
             ///< read once per file: its index in Scene::textures, -1 none (std::int32_t)
};

/// The range of a Number property.
enum class Bound : std::uint8_t {
    Any,          ///< any finite number
    AtLeastZero,  ///< >= 0
    Positive,     ///< > 0
};

template <ValueKind K> struct ValueTypeOf;
template <> struct ValueTypeOf<ValueKind::Number> { using type = double; };
template <> struct ValueTypeOf<ValueKind::Colour> { using type = glm::dvec3; };
template <> struct ValueTypeOf<ValueKind::Flag> { using type = bool; };
template <> struct ValueTypeOf<ValueKind::Image> { using type = std::int32_t; };
/// The C++ type a value of kind K is stored as.
template <ValueKind K>
using ValueType = typename ValueTypeOf<K>::type;

/// What a property says of itself: its scene-format key (distinct from every other
/// property's), the kind of value it takes, and for a Number its range.
struct PropertyInfo {
    std::string_view key;
    ValueKind kind;
    Bound bound = Bound::Any;
    bool meshes_only = false;  ///< the scene reader refuses it on the closed-form shapes
};

/// A material property declares
///   info    its PropertyInfo (a Bound only on a Number)
///   field   a pointer to its data member, of type ValueType<info.kind>, whose initialiser is
///           the default
/// and may declare
///   given   a pointer to a bool member set to true when the key is given (the checker:
///           `checker=R,G,B` turns the pattern on; its colour alone cannot say so)
template <class P>
concept MaterialPropertyDefinition = std::default_initializable<P> && requires(const P& p) {
    { P::info } -> std::convertible_to<PropertyInfo>;
    requires std::same_as<std::remove_cvref_t<decltype(p.*P::field)>, ValueType<P::info.kind>>;
    requires P::info.kind == ValueKind::Number || P::info.bound == Bound::Any;
};

/// Whether P sets a `given` flag when its key is given.
template <class P>
constexpr bool has_given_flag() {
    return requires(const P& p) {
        { p.*P::given } -> std::convertible_to<const bool&>;
    };
}

/// P's default value: the initialiser of its field.
template <class P>
ValueType<P::info.kind> default_of() {
    return P{}.*P::field;
}

}  // namespace streamrt
