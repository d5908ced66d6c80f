// The registry of material properties (materials/materials.h), property by property: every
// registered key is read by the material and shape statements into its field, its value
// checked at the value's line:column, named in the unknown-key message, counted by the
// material's equality and hash, and listed with its type, default and range in the material
// keys' table of docs/scene-format.md.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/format_number.h"
#include "materials/materials.h"
#include "scene/expect_error.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

/// The scenes' folder: Image properties read its textures/tiles.png (the scene text itself is
/// parsed from memory under this name).
const std::string kScenePath = std::string(STREAMRT_SOURCE_DIR) + "/scenes/registry_test.cfg";

std::string colour_text(const glm::dvec3& c) { return fmt_num(c.x) + "," + fmt_num(c.y) + "," + fmt_num(c.z); }

/// What each property must do, written out by hand from docs/scene-format.md's material keys
/// (not read from the registry under test, whose wrong bound or default would otherwise be
/// expected back): a value other than the default as written in a scene, the documented
/// default, a value its check refuses and a piece of that message.
struct Expected {
    std::string value, default_value, refused, message;
};
const std::map<std::string, Expected> kExpected = {
    {"ambi", {"1.5", "1", "-0.5", "must be >= 0"}},
    {"diff", {"1.5", "1", "-0.5", "must be >= 0"}},
    {"spec", {"0.5", "0", "-0.5", "must be >= 0"}},
    {"shininess", {"32.5", "32", "-0.5", "must be >= 0"}},
    {"refl", {"0.5", "0", "-0.5", "must be >= 0"}},
    {"trans", {"0.5", "0", "-0.5", "must be >= 0"}},
    {"ior", {"1.5", "1", "0", "must be > 0"}},
    {"checker", {"0.25,0.5,0.75", "", "0,-1,0", "must be >= 0"}},  // off until given
    {"cell", {"1.5", "1", "0", "must be > 0"}},
    {"fresnel", {"true", "false", "yes", "expected true or false"}},
    {"texture", {"textures/tiles.png", "", "missing.png", "cannot open texture file"}},  // the scene's texture 0
    {"uvscale", {"1.5", "1", "0", "must be > 0"}},
    {"vertex_colors", {"true", "false", "yes", "expected true or false"}},
    {"emission", {"0.25,0.5,0.75", "0,0,0", "0,-1,0", "must be >= 0"}},
};

/// A value of P's kind as written in a scene, converted here (not by the reader under test).
template <class P>
ValueType<P::info.kind> value_of(const std::string& text) {
    constexpr ValueKind kind = P::info.kind;
    if constexpr (kind == ValueKind::Number) {
        return std::stod(text);
    } else if constexpr (kind == ValueKind::Colour) {
        glm::dvec3 c;
        char comma;
        std::istringstream(text) >> c.x >> comma >> c.y >> comma >> c.z;
        return c;
    } else if constexpr (kind == ValueKind::Flag) {
        return text == "true";
    } else {
        return 0;  // an image file: the scene's first texture
    }
}

// What the material keys' table of docs/scene-format.md says of a property of this kind.
std::string doc_type(ValueKind k) {
    switch (k) {
        case ValueKind::Number: return "number";
        case ValueKind::Colour: return "colour";
        case ValueKind::Flag: return "`true` or `false`";
        case ValueKind::Image: return "path";
    }
    return "?";
}
template <class P>
std::string doc_default() {
    if constexpr (has_given_flag<P>() || P::info.kind == ValueKind::Image) return "—";  // off until given
    else if constexpr (P::info.kind == ValueKind::Number) return fmt_num(default_of<P>());
    else if constexpr (P::info.kind == ValueKind::Colour) return "`" + colour_text(default_of<P>()) + "`";
    else return default_of<P>() ? "`true`" : "`false`";
}
std::string doc_range(const PropertyInfo& info) {
    switch (info.kind) {
        case ValueKind::Number:
            return info.bound == Bound::Positive ? "> 0" : info.bound == Bound::AtLeastZero ? "≥ 0" : "";
        case ValueKind::Colour: return "components ≥ 0, at most 3.4e38 (single precision)";
        case ValueKind::Flag: return "";
        case ValueKind::Image: return "PNG or JPEG file";
    }
    return "?";
}

struct DocRow {
    std::string key, type, default_value, range;
};

/// The rows of the material keys' table (docs/scene-format.md, "Materials"), in order.
std::vector<DocRow> documented_material_keys() {
    std::ifstream in(fs::path(STREAMRT_SOURCE_DIR) / "docs" / "scene-format.md");
    REQUIRE(in);
    std::vector<DocRow> rows;
    std::string line;
    bool in_section = false;
    while (std::getline(in, line)) {
        if (line.rfind("Material keys (accepted by", 0) == 0) in_section = true;
        else if (in_section && !rows.empty() && line.empty()) break;
        if (!in_section || line.rfind("| `", 0) != 0) continue;
        std::vector<std::string> cells;
        std::stringstream s(line.substr(1));
        for (std::string cell; std::getline(s, cell, '|');) {
            const auto b = cell.find_first_not_of(' '), e = cell.find_last_not_of(' ');
            cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
        }
        REQUIRE(cells.size() >= 5);
        rows.push_back({cells[0].substr(1, cells[0].size() - 2), cells[1], cells[2], cells[3]});
    }
    return rows;
}

// What the concept refuses (materials/material_property.h), at compile time.
struct NoField {
    static constexpr PropertyInfo info{"x", ValueKind::Number};
    double x = 0.0;
};
struct WrongType {
    static constexpr PropertyInfo info{"x", ValueKind::Colour};
    double x = 0.0;
    static constexpr auto field = &WrongType::x;
};
struct BoundOnAFlag {
    static constexpr PropertyInfo info{"x", ValueKind::Flag, Bound::Positive};
    bool x = false;
    static constexpr auto field = &BoundOnAFlag::x;
};
static_assert(!MaterialPropertyDefinition<NoField>);
static_assert(!MaterialPropertyDefinition<WrongType>);
static_assert(!MaterialPropertyDefinition<BoundOnAFlag>);
static_assert(MaterialPropertyDefinition<property::Emission>);
static_assert(MaterialPropertyDefinition<property::Checker> && has_given_flag<property::Checker>());
static_assert(!PropertyList<property::Refl, property::Refl>::distinct_keys());

}  // namespace

TEST_CASE("material registry: keys are distinct and the list is the one the reader uses") {
    CHECK(MaterialProperties::distinct_keys());
    CHECK(MaterialProperties::size == kExpected.size());
    // The unknown-key message lists the object's colour, then every registered key in order
    // (docs/scene-format.md's table, written out here).
    const std::string keys =
        "color ambi diff spec shininess refl trans ior checker cell fresnel texture uvscale vertex_colors emission";
    test::expect_error("material m bogus=1", 1, 12,
                       "unknown key 'bogus' for 'material' (expected one of: " + keys + " material)");
    test::expect_error("sphere bogus=1", 1, 8, "(expected one of: material " + keys + " scale");
}

TEST_CASE("material registry: every property is read by material and shape statements, and checked") {
    MaterialProperties::for_each([&](auto p) {
        using P = decltype(p);
        const std::string key(P::info.key);
        CAPTURE(key);
        const auto expected = kExpected.find(key);
        REQUIRE(expected != kExpected.end());  // a new property needs its expectations here
        const std::string text = expected->second.value;
        const auto value = value_of<P>(text);
        // A property for meshes only (vertex_colors) is tried on a mesh with what it needs.
        const std::string shape = P::info.meshes_only ? "mesh file=meshes/colored_sphere.ply" : "sphere";
        const Scene s = parse_scene("material m " + key + "=" + text + "\n" + shape + " material=m\n" + shape + " " +
                                        key + "=" + text + "\n" + shape + "\n",
                                    kScenePath);
        REQUIRE(s.objects.size() == 3);
        for (int i : {0, 1}) {
            const Material& m = s.material_of(s.objects[std::size_t(i)]);
            CHECK(m.*P::field == value);
            if constexpr (has_given_flag<P>()) CHECK(m.*P::given);
            // Equality and hash count this property: the record differs from the default one.
            CHECK_FALSE(m == Material{});
            CHECK(MaterialHash{}(m) != MaterialHash{}(Material{}));
        }
        if constexpr (has_given_flag<P>() && P::info.kind == ValueKind::Colour) {
            // Given with the default value, the key still turns the property on: another record.
            const Scene g = parse_scene("sphere " + key + "=" + colour_text(default_of<P>()) + "\nsphere\n", kScenePath);
            CHECK(g.materials.size() == 2);
            CHECK_FALSE(g.material_of(g.objects[0]) == g.material_of(g.objects[1]));
            CHECK(MaterialHash{}(g.material_of(g.objects[0])) != MaterialHash{}(g.material_of(g.objects[1])));
        }
        if (!expected->second.default_value.empty())
            CHECK(s.material_of(s.objects[2]).*P::field == value_of<P>(expected->second.default_value));
        CHECK(s.material_of(s.objects[2]) == Material{});
        CHECK(s.materials.size() == 2);
        // The property's check, at its value's column (shape + " " + key + "=").
        test::expect_error_in(kScenePath, shape + " " + key + "=" + expected->second.refused, 1,
                              int(shape.size() + 2 + key.size() + 1), expected->second.message);
    });
}

TEST_CASE("material registry: docs/scene-format.md lists every property with its type, default and range") {
    const std::vector<DocRow> rows = documented_material_keys();
    REQUIRE(!rows.empty());
    // The table: color (the object's own colour, not a material record's field) first, then
    // the registered properties in the registry's order, and nothing else.
    CHECK(rows.front().key == "color");
    std::size_t i = 1;
    MaterialProperties::for_each([&](auto p) {
        using P = decltype(p);
        const std::string key(P::info.key);
        CAPTURE(key);
        REQUIRE(i < rows.size());
        const DocRow& row = rows[i++];
        CHECK(row.key == key);
        CHECK(row.type == doc_type(P::info.kind));
        CHECK(row.default_value == doc_default<P>());
        CHECK(row.range == doc_range(P::info));
    });
    CHECK(i == rows.size());
}
