#pragma once
// The scene format's key vocabularies (docs/scene-format.md lists the same), what a material
// key or a transform key does, and the statement words. Internal to the reader.
#include <algorithm>
#include <array>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/statement.h"
#include "shapes/shapes.h"

namespace streamrt::scene_reader {

// ---- key vocabularies ------------------------------------------------------------------
/// The material keys: the object's colour, then every registered material property's key
/// (materials/materials.h), in its order.
inline const std::vector<std::string_view> kMaterialKeys = [] {
    std::vector<std::string_view> keys{"color"};
    MaterialProperties::for_each([&](auto p) { keys.push_back(decltype(p)::info.key); });
    return keys;
}();
inline const std::vector<std::string_view> kTransformKeys = {"scale", "rotate_x", "rotate_y", "rotate_z",
                                                      "translate"};
inline const std::vector<std::string_view> kImageKeys = {"width",  "height",  "spp",
                                                  "depth",  "degree",  "output",
                                                  "sampler", "calibration", "cutoff",
                                                  "colorspace", "exposure", "tonemap", "exr",
                                                  "frames", "adaptive"};
inline const std::vector<std::string_view> kLookAtKeys = {"eye", "look", "up", "fov"};
inline const std::vector<std::string_view> kExplicitCameraKeys = {"rx",       "ry",       "df",
                                                           "scale",    "rotate_x", "rotate_y",
                                                           "rotate_z", "translate"};
/// Depth of field: keys of both camera forms.
inline const std::vector<std::string_view> kLensKeys = {"aperture", "focus"};

inline std::vector<std::string_view> join(std::initializer_list<std::vector<std::string_view>> lists) {
    std::vector<std::string_view> out;
    for (const auto& l : lists) out.insert(out.end(), l.begin(), l.end());
    return out;
}

// The joined lists, built once (the order is the one messages list them in).
inline const std::vector<std::string_view> kCameraKeys = join({kLookAtKeys, kExplicitCameraKeys, kLensKeys, {"name"}});
inline const std::vector<std::string_view> kMaterialStatementKeys = join({kMaterialKeys, {"material"}});
inline const std::vector<std::string_view> kShapeKeys = join({{"material"}, kMaterialKeys, kTransformKeys, {"name"}});
/// A csg block's keys: what its children inherit (docs/scene-format.md, "CSG").
inline const std::vector<std::string_view> kCsgKeys = join({{"material", "name"}, kMaterialKeys, kTransformKeys});
inline const std::vector<std::string_view> kMeshKeys = join({kShapeKeys, {"file", "smooth", "materials"}});
// The `key` statement's keys, by what the name names (animation, scene/animation.h).
inline const std::vector<std::string_view> kObjectKeyKeys = {"frame", "translate", "rotate", "scale"};
inline const std::vector<std::string_view> kLightKeyKeys = {"frame", "pos", "color"};
inline const std::vector<std::string_view> kCameraKeyKeys = {"frame", "eye", "look", "fov"};
inline const std::vector<std::string_view> kKeyKeys = join({kObjectKeyKeys, {"pos", "color", "eye", "look", "fov"}});

/// Each kind's keys: the common ones, plus its parameter key (shapes/shapes.h) or the mesh's.
inline const std::array<std::vector<std::string_view>, kShapeKindCount> kKeysOfKind = [] {
    std::array<std::vector<std::string_view>, kShapeKindCount> keys;
    for (int k = 0; k < kShapeKindCount; ++k) {
        const ShapeParam p = shape_param(ShapeKind(k));
        keys[std::size_t(k)] = p.present() ? join({kShapeKeys, {p.key}}) : kShapeKeys;
    }
    keys[std::size_t(ShapeKind::Mesh)] = kMeshKeys;
    return keys;
}();

inline const std::vector<std::string_view>& shape_keys(ShapeKind kind) { return kKeysOfKind[std::size_t(kind)]; }

inline bool contains(const std::vector<std::string_view>& v, std::string_view k) {
    return std::find(v.begin(), v.end(), k) != v.end();
}

/// What a `material` statement names and a shape's material keys set: the optical
/// parameters and the colour (stored apart in the scene: Object::color, Scene::materials).
struct Appearance {
    Material m;
    glm::dvec3 color{1.0, 1.0, 1.0};
};

/// Reads a's value as property P's kind of value into m, checked (materials/material_property.h;
/// each refusal at the value's file:line:col). An Image value is a file: `load_image(a)` reads
/// it (once per file: the Parser's) and gives its index in Scene::textures.
template <class P, class LoadImage>
void read_property(const Statement& st, const Arg& a, Material& m, const LoadImage& load_image) {
    auto& v = m.*P::field;
    constexpr PropertyInfo info = P::info;
    if constexpr (info.kind == ValueKind::Number) {
        if constexpr (info.bound == Bound::AtLeastZero) v = st.at_least_zero(a);
        else if constexpr (info.bound == Bound::Positive) v = st.positive(a);
        else v = st.number(a);
    } else if constexpr (info.kind == ValueKind::Colour) {
        v = st.color(a);
    } else if constexpr (info.kind == ValueKind::Flag) {
        v = st.boolean(a);
    } else {
        static_assert(info.kind == ValueKind::Image);
        v = load_image(a);
    }
    if constexpr (has_given_flag<P>()) m.*P::given = true;
}

/// Applies one material key (the colour or a registered property); false when `a` is not a
/// material key.
template <class LoadImage>
bool apply_material_key(const Statement& st, const Arg& a, Appearance& ap, const LoadImage& load_image) {
    if (same(a.key, "color")) {
        ap.color = st.color(a);
        return true;
    }
    return MaterialProperties::visit_key(a.key, [&](auto p) { read_property<decltype(p)>(st, a, ap.m, load_image); });
}

/// Applies one transform key on the left of `md` (written order = application order).
inline bool apply_transform_key(const Statement& st, const Arg& a, glm::dmat4& md) {
    const auto k = a.key;
    glm::dmat4 t;
    // Scale and translate, the common keys, touch only what they change: the same values as
    // the full products S Md and T Md of an affine Md (the skipped terms are exact zeros).
    if (same(k, "scale")) {
        const glm::dvec3 s = st.scale(a);
        for (int c = 0; c < 4; ++c) md[c] *= glm::dvec4(s, 1.0);
        return true;
    }
    if (same(k, "translate")) {
        const glm::dvec3 v = st.vec3(a);
        for (int c = 0; c < 4; ++c) md[c] += glm::dvec4(v * md[c][3], 0.0);
        return true;
    }
    if (same(k, "rotate_x")) t = rotate_x_matrix(st.number(a));
    else if (same(k, "rotate_y")) t = rotate_y_matrix(st.number(a));
    else if (same(k, "rotate_z")) t = rotate_z_matrix(st.number(a));
    else return false;
    md = t * md;
    return true;
}

inline std::optional<ShapeKind> shape_from_word(std::string_view w) { return canonical_shape_named(w); }

/// The statement words, in the order the unknown-statement message lists them (and the
/// names a mistyped word is matched against).
inline const std::vector<std::string> kStatementWords = [] {
    std::vector<std::string> words = {"image", "ambient", "background", "camera", "light", "material", "key"};
    CanonicalShapes::for_each([&](auto s) { words.emplace_back(s.name); });
    words.emplace_back("mesh");
    words.emplace_back("include");
    words.emplace_back("csg");
    return words;
}();
inline const std::string kStatementList = [] {
    std::string list;
    for (std::size_t i = 0; i < kStatementWords.size(); ++i)
        list += (i == 0 ? "" : i + 1 == kStatementWords.size() ? " or " : ", ") + kStatementWords[i];
    return list;
}();

/// The statement words the chunked reader parses in parallel (mesh and include fall back to
/// one sequential pass: they read other files).
inline bool is_plain_shape(std::string_view w) { return shape_from_word(w).has_value(); }

}  // namespace streamrt::scene_reader
