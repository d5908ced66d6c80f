// The material key emission=R,G,B: values, defaults, materials that differ only by it, and
// each refusal at the exact line:column of its value.
#include <doctest/doctest.h>

#include <string>

#include "scene/expect_error.h"
#include "scene/parser.h"

using namespace streamrt;

using test::expect_error;  // scene/expect_error.h

TEST_CASE("parser: emission= on materials and shapes") {
    const Scene s = parse_scene("material lamp ambi=0 diff=0 emission=1,0.5,0.25\nsphere material=lamp\n"
                                "sphere material=lamp emission=0,0,2\nsphere\nsphere emission=+0.5,0,1e3\n",
                                "t.cfg");
    REQUIRE(s.objects.size() == 4);
    CHECK(s.material_of(s.objects[0]).emission == glm::dvec3(1, 0.5, 0.25));
    CHECK(s.material_of(s.objects[1]).emission == glm::dvec3(0, 0, 2));  // the shape's key over the material's
    CHECK(s.material_of(s.objects[2]).emission == glm::dvec3(0, 0, 0));  // the default: black
    CHECK(s.material_of(s.objects[3]).emission == glm::dvec3(0.5, 0, 1000));
    // Materials that differ only by their emission are separate records.
    const Scene t = parse_scene("sphere emission=0.1,0.1,0.1\nsphere emission=0.2,0.1,0.1\nsphere\n"
                                "sphere emission=0.1,0.1,0.1\n",
                                "t.cfg");
    CHECK(t.materials.size() == 3);
    CHECK(t.objects[0].material == t.objects[3].material);
}

TEST_CASE("parser: bad emission values fail at their file:line:col") {
    // "sphere emission=" puts the value at column 17.
    expect_error("sphere emission=0.1,-0.2,0.3", 1, 17, "colour components of 'emission' must be >= 0, got '0.1,-0.2,0.3'");
    expect_error("sphere emission=-1,0,0", 1, 17, "must be >= 0");
    // Not finite: infinity, NaN and a number beyond double's range are not numbers here.
    for (const char* v : {"inf,0,0", "0,nan,0", "0,0,1e999", "0,-inf,0"})
        expect_error(std::string("sphere emission=") + v, 1, 17,
                     std::string("expected 3 comma-separated numbers x,y,z for 'emission', got '") + v + "'");
    // Beyond single precision (the engines' colours).
    expect_error("sphere emission=1e39,0,0", 1, 17, "colour components of 'emission' must be at most 3.4e38");
    // Wrong counts and empty components.
    for (const char* v : {"0.5", "1,2", "1,2,3,4", "1,,2", "1,2,"})
        expect_error(std::string("sphere emission=") + v, 1, 17, "expected 3 comma-separated numbers x,y,z for 'emission'");
    expect_error("sphere emission=", 1, 17, "empty value for 'emission'");
    // In a material statement, on a later line, after other keys.
    expect_error("image width=4 height=4\n\nmaterial lamp ambi=0 emission=1,1", 3, 31,
                 "expected 3 comma-separated numbers x,y,z for 'emission', got '1,1'");
    // Given twice.
    expect_error("sphere emission=1,1,1 emission=0,0,0", 1, 23, "duplicate key 'emission'");
}
