// The light statement's area-light, falloff and soft-edge keys: values land in the fields,
// bad values are one error at the exact line and column.
#include <doctest/doctest.h>

#include <string>

#include "scene/parser.h"

using namespace streamrt;

namespace {

void expect_light_error(const std::string& text, int line, int column, const std::string& needle) {
    INFO("scene text: ", text);
    bool thrown = false;
    try {
        parse_scene(text, "l.cfg");
    } catch (const SceneError& e) {
        thrown = true;
        INFO("message: ", std::string(e.what()));
        CHECK(e.where().line == line);
        CHECK(e.where().column == column);
        CHECK(e.message().find(needle) != std::string::npos);
    }
    CHECK_MESSAGE(thrown, "expected a SceneError");
}

}  // namespace

TEST_CASE("area lights: keys land in the light") {
    const Scene s = parse_scene(
        "light sphere pos=1,2,3 radius=0.5 color=0.5,0.25,1 samples=9 falloff=inverse_square\n"
        "light rect pos=0,4,0 u=2,0,0 v=0,0,1 samples=4\n"
        "light spot pos=0,5,0 dir=0,-1,0 angle=30 soft=10\n"
        "light point pos=0,1,0\n",
        "l.cfg");
    REQUIRE(s.lights.size() == 4);
    const Light& sp = s.lights[0];
    CHECK(sp.kind == LightKind::Sphere);
    CHECK(sp.pos == glm::dvec3(1, 2, 3));
    CHECK(sp.radius == 0.5);
    CHECK(sp.samples == 9);
    CHECK(sp.falloff == Falloff::InverseSquare);
    CHECK(sp.is_area());
    const Light& r = s.lights[1];
    CHECK(r.kind == LightKind::Rect);
    CHECK(r.u == glm::dvec3(2, 0, 0));
    CHECK(r.v == glm::dvec3(0, 0, 1));
    CHECK(r.samples == 4);
    CHECK(r.falloff == Falloff::None);
    CHECK(s.lights[2].soft == 10.0);
    CHECK(s.lights[2].shaped());
    // The handout's lights stay on their original path.
    CHECK_FALSE(s.lights[3].shaped());
}

TEST_CASE("area lights: a disk light's keys land in the light") {
    const Scene s = parse_scene("light disk pos=1,3,0 dir=0,-2,0 radius=0.75 samples=8 color=2,2,2\n", "l.cfg");
    REQUIRE(s.lights.size() == 1);
    const Light& d = s.lights[0];
    CHECK(d.kind == LightKind::Disk);
    CHECK(d.pos == glm::dvec3(1, 3, 0));
    CHECK(d.dir == glm::dvec3(0, -1, 0));  // normalised
    CHECK(d.radius == 0.75);
    CHECK(d.samples == 8);
    CHECK(d.is_area());
    CHECK(d.shaped());
}

TEST_CASE("area lights: bad values at their line and column") {
    expect_light_error("light disk pos=0,0,0 dir=0,-1,0\n", 1, 1, "light disk needs 'radius=r'");
    expect_light_error("light disk pos=0,0,0 radius=1\n", 1, 1, "light disk needs 'dir=x,y,z'");
    expect_light_error("light disk dir=0,-1,0 radius=1\n", 1, 1, "light disk needs 'pos=x,y,z'");
    expect_light_error("light disk pos=0,0,0 dir=0,-1,0 radius=1 u=1,0,0\n", 1, 42, "unknown key 'u'");
    expect_light_error("ambient 0.1\nlight sphere pos=0,0,0 radius=-1\n", 2, 31, "'radius' must be > 0");
    expect_light_error("light sphere pos=0,0,0 radius=0\n", 1, 31, "'radius' must be > 0");
    expect_light_error("light sphere pos=0,0,0\n", 1, 1, "needs 'radius=r'");
    expect_light_error("light rect pos=0,0,0 u=1,0,0 v=2,0,0\n", 1, 32, "span no area");
    expect_light_error("light rect pos=0,0,0 u=0,0,0 v=0,0,1\n", 1, 32, "span no area");
    expect_light_error("light rect pos=0,0,0 u=1,0,0\n", 1, 1, "needs 'v=x,y,z'");
    expect_light_error("light sphere pos=0,0,0 radius=1 samples=0\n", 1, 41, "'samples' must be in [1, 4096]");
    expect_light_error("light rect pos=0,0,0 u=1,0,0 v=0,1,0 samples=2.5\n", 1, 46, "expected an integer");
    expect_light_error("light spot pos=0,0,0 dir=0,-1,0 angle=20 soft=20\n", 1, 47, "'soft' must be below");
    expect_light_error("light spot pos=0,0,0 dir=0,-1,0 angle=20 soft=-1\n", 1, 47, "'soft' must be >= 0");
    expect_light_error("light point pos=0,0,0 falloff=linear\n", 1, 31, "none or inverse_square");
    expect_light_error("light point pos=0,0,0 soft=5\n", 1, 23, "unknown key 'soft'");
    expect_light_error("light sphere pos=0,0,0 radius=1 dir=0,1,0\n", 1, 33, "unknown key 'dir'");
    expect_light_error("light disco pos=0,0,0\n", 1, 7, "(point, spot, directional, sphere, rect or disk), got 'disco'");
}
