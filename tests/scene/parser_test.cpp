// The .cfg reader: every key lands in the right field, every mistake is reported at the
// exact line and column.
#include <doctest/doctest.h>

#include <algorithm>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "scene/expect_error.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

constexpr double kEps = 1e-9;

bool near(const glm::dvec3& a, const glm::dvec3& b, double eps = kEps) {
    return glm::length(a - b) <= eps;
}

glm::dvec3 apply(const glm::dmat4& m, const glm::dvec3& p) {
    return glm::dvec3(m * glm::dvec4(p, 1.0));
}

Scene parse(const std::string& text) { return parse_scene(text, "t.cfg"); }

using test::expect_error;  // scene/expect_error.h

/// A fresh temporary directory removed at scope exit.
struct TempDir {
    fs::path dir;
    TempDir() {
        static int counter = 0;
        dir = fs::temp_directory_path() /
              ("streamrt_parser_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    fs::path write(const std::string& name, const std::string& text) const {
        const fs::path p = dir / name;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
};

}  // namespace

TEST_CASE("parser: defaults of an empty scene") {
    const Scene s = parse("# nothing\n\n   \n");
    CHECK(s.path == "t.cfg");
    CHECK(s.objects.empty());
    CHECK(s.lights.empty());
    CHECK(s.settings.width == 640);
    CHECK(s.settings.height == 480);
    CHECK(s.settings.ambient == doctest::Approx(0.1));
    CHECK_FALSE(s.camera.look_at);
}

TEST_CASE("parser: image settings") {
    const Scene s = parse(
        "image width=320 height=200 spp=16 depth=7 degree=3 output=pic.pfm sampler=grid "
        "calibration=normalize\n");
    CHECK(s.settings.width == 320);
    CHECK(s.settings.height == 200);
    CHECK(s.settings.spp == 16);
    CHECK(s.settings.depth == 7);
    CHECK(s.settings.degree == 3);
    CHECK(s.settings.output == "pic.pfm");
    CHECK(s.settings.pattern == SamplePattern::Grid);
    CHECK(s.settings.calibration == Calibration::Normalize);

    CHECK(parse("image sampler=random").settings.pattern == SamplePattern::Random);
    CHECK(parse("image sampler=stratified").settings.pattern == SamplePattern::Stratified);
    CHECK(parse("image calibration=clamp").settings.calibration == Calibration::Clamp);
    // Display colour (docs/scene-format.md, "Output and display colour"): defaults, then each key.
    const RenderSettings def = parse("").settings;
    CHECK(def.colorspace == ColorSpace::Srgb);
    CHECK(def.tonemap == Tonemap::Clamp);
    CHECK(def.exposure == 1.0);
    CHECK(def.exr == ExrPixels::Half);
    const RenderSettings d = parse("image colorspace=linear tonemap=reinhard exposure=2.5 exr=float").settings;
    CHECK(d.colorspace == ColorSpace::Linear);
    CHECK(d.tonemap == Tonemap::Reinhard);
    CHECK(d.exposure == 2.5);
    CHECK(d.exr == ExrPixels::Float);
    CHECK(parse("image colorspace=srgb tonemap=clamp exr=half").settings.colorspace == ColorSpace::Srgb);
    CHECK(parse("image exposure=1e-6").settings.exposure == 1e-6);
    CHECK(parse("image exposure=1e6").settings.exposure == 1e6);
    // Limits are inclusive.
    const Scene lim = parse("image width=1 height=32768 spp=65536 depth=0 degree=0");
    CHECK(lim.settings.width == 1);
    CHECK(lim.settings.height == 32768);
    CHECK(lim.settings.spp == 65536);
    CHECK(lim.settings.depth == 0);
    CHECK(lim.settings.degree == 0);
    // A later image statement only changes the keys it gives.
    const Scene two = parse("image width=10 height=20\nimage spp=2\n");
    CHECK(two.settings.width == 10);
    CHECK(two.settings.height == 20);
    CHECK(two.settings.spp == 2);
}

TEST_CASE("parser: ambient and background") {
    const Scene s = parse("ambient 0.25\nbackground 0.02,0.03,0.05   # night\n");
    CHECK(s.settings.ambient == doctest::Approx(0.25));
    CHECK(near(s.settings.background, {0.02, 0.03, 0.05}));
    CHECK(parse("ambient 0").settings.ambient == 0.0);
    CHECK(parse("ambient 1").settings.ambient == 1.0);
    CHECK(parse("ambient +0.5").settings.ambient == 0.5);
    CHECK(parse("ambient 5e-1").settings.ambient == 0.5);
}

TEST_CASE("parser: look-at camera") {
    const Scene s = parse("camera eye=0,1,6 look=0,0.5,0 up=0,2,0 fov=45\n");
    const Camera& c = s.camera;
    CHECK(c.look_at);
    CHECK(near(c.eye, {0, 1, 6}));
    CHECK(near(c.look, {0, 0.5, 0}));
    CHECK(near(c.up, {0, 1, 0}));  // normalised
    CHECK(c.fov == doctest::Approx(45.0));
    // The canonical eye lands on `eye`, the screen centre one unit towards `look`.
    const glm::dmat4 md = c.world_from_canonical(640, 480);
    CHECK(near(apply(md, {0, 0, 1}), {0, 1, 6}));
    const glm::dvec3 fwd = glm::normalize(glm::dvec3(0, -0.5, -6));
    CHECK(near(apply(md, {0, 0, 0}), glm::dvec3(0, 1, 6) + fwd));
}

TEST_CASE("parser: explicit camera") {
    const Scene s = parse("camera rx=1 ry=0.75 df=2 rotate_x=-10 translate=0,1,6\n");
    const Camera& c = s.camera;
    CHECK_FALSE(c.look_at);
    const double t = 10.0 * std::numbers::pi / 180.0;
    // Md = T * Rx(-10) * S(1, 0.75, 2): the canonical eye (0,0,1) goes to (0,0,2) and then ...
    CHECK(near(apply(c.md, {0, 0, 1}), {0, 1 + 2 * std::sin(t), 6 + 2 * std::cos(t)}));
    CHECK(near(apply(c.md, {0, 0, 0}), {0, 1, 6}));
    CHECK(near(apply(c.md, {1, 1, 0}), {1, 1 + 0.75 * std::cos(t), 6 - 0.75 * std::sin(t)}));
    CHECK(c.world_from_canonical(10, 10) == c.md);

    // Defaults rx=ry=df=1: a bare translate only moves the canonical camera.
    const Scene d = parse("camera translate=1,2,3");
    CHECK(near(apply(d.camera.md, {0, 0, 1}), {1, 2, 4}));
    CHECK(near(apply(d.camera.md, {1, -1, 0}), {2, 1, 3}));
    // The homothety comes first whatever the order the keys are written in.
    const Scene e = parse("camera translate=0,0,5 df=3 scale=2");
    CHECK(near(apply(parse("camera df=3 scale=2 translate=0,0,5").camera.md, {0, 0, 1}), {0, 0, 11}));
    CHECK(near(apply(e.camera.md, {0, 0, 1}), {0, 0, 16}));  // H, then T, then S
    // A later camera statement replaces the earlier one entirely.
    const Scene r = parse("camera eye=1,2,3 look=0,0,0\ncamera df=4\n");
    CHECK_FALSE(r.camera.look_at);
    CHECK(near(apply(r.camera.md, {0, 0, 1}), {0, 0, 4}));
    const Scene r2 = parse("camera df=4\ncamera eye=1,2,3\n");
    CHECK(r2.camera.look_at);
    CHECK(near(r2.camera.eye, {1, 2, 3}));
    CHECK(r2.camera.md == glm::dmat4(1.0));
}

TEST_CASE("parser: lights") {
    const Scene s = parse(
        "light point pos=5,8,5 color=1,0.5,0.25\n"
        "light spot pos=0,5,0 dir=0,-2,0 angle=30\n"
        "light directional dir=-1,-1,-1 color=0.5,0.5,0.5\n"
        "light point pos=1,2,3\n");
    REQUIRE(s.lights.size() == 4);
    CHECK(s.lights[0].kind == LightKind::Point);
    CHECK(near(s.lights[0].pos, {5, 8, 5}));
    CHECK(near(s.lights[0].color, {1, 0.5, 0.25}));
    CHECK(s.lights[1].kind == LightKind::Spot);
    CHECK(near(s.lights[1].pos, {0, 5, 0}));
    CHECK(near(s.lights[1].dir, {0, -1, 0}));
    CHECK(s.lights[1].angle == doctest::Approx(30.0));
    CHECK(near(s.lights[1].color, {1, 1, 1}));
    CHECK(s.lights[2].kind == LightKind::Directional);
    CHECK(near(s.lights[2].dir, glm::dvec3(-1, -1, -1) / std::sqrt(3.0)));
    CHECK(near(s.lights[2].color, {0.5, 0.5, 0.5}));
    CHECK(near(s.lights[3].color, {1, 1, 1}));
    // Over-bright lights are allowed.
    CHECK(near(parse("light point pos=0,0,0 color=3,3,3").lights[0].color, {3, 3, 3}));
}

TEST_CASE("parser: materials and shapes") {
    const Scene s = parse(
        "material glass color=1,1,1 ambi=0 diff=0 spec=0.5 shininess=64 refl=0.1 trans=0.9 "
        "ior=1.5\n"
        "sphere material=glass scale=1 translate=0,1,0\n"
        "cube color=1,0,0 ambi=0.2 diff=0.8 scale=0.5,1,0.5 rotate_y=45 translate=2,0.5,0\n"
        "torus minor=0.25 color=0.9,0.7,0.2 diff=0.8 rotate_x=90 translate=-2,1,0\n"
        "cylinder color=0.2,0.8,0.3 diff=0.8 scale=0.5,1,0.5\n"
        "cone color=0.3,0.3,0.9 diff=0.8 translate=0,1,-3\n"
        "plane color=0.8,0.8,0.8 checker=0.2,0.2,0.2 cell=0.5 diff=0.9\n");
    REQUIRE(s.objects.size() == 6);
    const ShapeKind kinds[] = {ShapeKind::Sphere, ShapeKind::Cube, ShapeKind::Torus,
                               ShapeKind::Cylinder, ShapeKind::Cone, ShapeKind::Plane};
    for (int i = 0; i < 6; ++i) {
        CHECK(s.objects[i].kind == kinds[i]);
        CHECK(s.where(i).file == "t.cfg");
        CHECK(s.where(i).line == i + 2);
        CHECK(s.where(i).column == 1);
    }
    const Material& g = s.material_of(s.objects[0]);
    CHECK(near(glm::dvec3(s.objects[0].color), {1, 1, 1}));
    CHECK(g.ambi == 0.0);
    CHECK(g.diff == 0.0);
    CHECK(g.spec == doctest::Approx(0.5));
    CHECK(g.shininess == doctest::Approx(64));
    CHECK(g.refl == doctest::Approx(0.1));
    CHECK(g.trans == doctest::Approx(0.9));
    CHECK(g.ior == doctest::Approx(1.5));
    CHECK_FALSE(g.checker);
    CHECK(near(apply(s.objects[0].direct(), {0, 0, 0}), {0, 1, 0}));

    const Material& red = s.material_of(s.objects[1]);
    CHECK(near(glm::dvec3(s.objects[1].color), {1, 0, 0}));
    CHECK(red.ambi == doctest::Approx(0.2));
    CHECK(red.diff == doctest::Approx(0.8));
    CHECK(red.spec == 0.0);  // defaults untouched
    CHECK(red.ior == 1.0);
    // scale (0.5,1,0.5) then rotate_y 45 then translate: canonical (1,0,0) -> (0.5,0,0) ->
    // (0.5cos45, 0, -0.5sin45) -> + (2,0.5,0).
    const double h = 0.5 * std::sqrt(0.5);
    CHECK(near(apply(s.objects[1].direct(), {1, 0, 0}), {2 + h, 0.5, -h}));
    // The engines' Mi (affine_inverse) is consistent with Md.
    const glm::dmat4 id = glm::dmat4(affine_inverse(s.objects[1].md)) * s.objects[1].direct();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) CHECK(id[c][r] == doctest::Approx(c == r ? 1.0 : 0.0));

    CHECK(s.objects[2].param == doctest::Approx(0.25));
    // rotate_x=90 takes +y to +z.
    CHECK(near(apply(s.objects[2].direct(), {0, 1, 0}), {-2, 1, 1}));

    const Material& floor = s.material_of(s.objects[5]);
    CHECK(floor.checker);
    CHECK(near(floor.checker_color, {0.2, 0.2, 0.2}));
    CHECK(floor.cell == doctest::Approx(0.5));
    CHECK(floor.diff == doctest::Approx(0.9));

    CHECK(parse("torus minor=0.4").objects[0].param == doctest::Approx(0.4));
}

TEST_CASE("parser: material= first, then direct keys override it") {
    const Scene s = parse(
        "material base color=0,0,1 diff=0.5 refl=0.3\n"
        "sphere color=1,0,0 material=base\n"   // the key before material= still wins
        "sphere material=base refl=0\n"
        "material derived material=base diff=0.25\n"
        "cube material=derived\n");
    REQUIRE(s.objects.size() == 3);
    CHECK(near(glm::dvec3(s.objects[0].color), {1, 0, 0}));
    CHECK(s.material_of(s.objects[0]).diff == doctest::Approx(0.5));
    CHECK(s.material_of(s.objects[0]).refl == doctest::Approx(0.3));
    CHECK(near(glm::dvec3(s.objects[1].color), {0, 0, 1}));
    CHECK(s.material_of(s.objects[1]).refl == 0.0);
    CHECK(near(glm::dvec3(s.objects[2].color), {0, 0, 1}));
    CHECK(s.material_of(s.objects[2]).diff == doctest::Approx(0.25));
    CHECK(s.material_of(s.objects[2]).refl == doctest::Approx(0.3));
}

TEST_CASE("parser: materials are stored once, colours stay with their objects") {
    const Scene s = parse(
        "material gloss color=0,1,0 spec=0.5\n"
        "sphere color=1,0,0 spec=0.5\n"     // gloss's parameters, its own colour
        "sphere color=0,0,1 spec=0.5\n"     // the same again, another colour
        "sphere color=1,0,0 spec=0.25\n"    // another material
        "cube material=gloss\n");           // gloss: the first material again
    REQUIRE(s.objects.size() == 4);
    REQUIRE(s.materials.size() == 2);  // in order of first use
    CHECK(s.materials[0].spec == 0.5);
    CHECK(s.materials[1].spec == 0.25);
    CHECK(s.objects[0].material == 0);
    CHECK(s.objects[1].material == 0);
    CHECK(s.objects[2].material == 1);
    CHECK(s.objects[3].material == 0);
    CHECK(s.objects[0].color == glm::vec3(1, 0, 0));
    CHECK(s.objects[1].color == glm::vec3(0, 0, 1));
    CHECK(s.objects[3].color == glm::vec3(0, 1, 0));
}

TEST_CASE("parser: transforms apply in written order") {
    const Scene s = parse(
        "sphere scale=2 translate=1,0,0\n"
        "sphere translate=1,0,0 scale=2\n"
        "sphere scale=1,2,3\n"
        "sphere rotate_z=90\n"
        "sphere rotate_y=90\n"
        "sphere rotate_x=90 rotate_y=90\n");
    REQUIRE(s.objects.size() == 6);
    CHECK(near(apply(s.objects[0].direct(), {1, 0, 0}), {3, 0, 0}));
    CHECK(near(apply(s.objects[1].direct(), {1, 0, 0}), {4, 0, 0}));
    CHECK(near(apply(s.objects[2].direct(), {1, 1, 1}), {1, 2, 3}));
    CHECK(near(apply(s.objects[3].direct(), {1, 0, 0}), {0, 1, 0}));   // x -> y
    CHECK(near(apply(s.objects[4].direct(), {0, 0, 1}), {1, 0, 0}));   // z -> x
    CHECK(near(apply(s.objects[5].direct(), {0, 1, 0}), {1, 0, 0}));   // y -> z -> x
    // Negative (mirroring) scales are fine.
    CHECK(near(apply(parse("cube scale=-1,1,1").objects[0].direct(), {1, 0, 0}), {-1, 0, 0}));
}

TEST_CASE("parser: whitespace, comments and CRLF") {
    const Scene s = parse(
        "\xEF\xBB\xBF# a comment\r\n"
        "\t sphere   color=1,0,0\t# trailing comment\r\n"
        "#sphere\n"
        "cube#glued comment\n");
    REQUIRE(s.objects.size() == 2);
    CHECK(s.where(0).line == 2);
    CHECK(s.where(0).column == 3);
    CHECK(s.where(1).line == 4);
}

// Proven against: the suggestion dropped from Statement::read_args (no "did you mean").
TEST_CASE("parser: an unknown key or statement near a known one names it") {
    const auto message = [](const std::string& text) {
        try {
            parse_scene(text, "t.cfg");
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(message("sphere colour=1,0,0").rfind("t.cfg:1:8: unknown key 'colour' for 'sphere': did you mean 'color'? "
                                               "(expected one of: ", 0) == 0);
    CHECK(message("camera eye=0,0,5 fvo=40").rfind("t.cfg:1:18: unknown key 'fvo' for 'camera': did you mean 'fov'? ",
                                                   0) == 0);
    CHECK(message("\nspheer color=1,0,0") ==
          "t.cfg:2:1: unknown statement 'spheer': did you mean 'sphere'? (expected image, ambient, background, camera, "
          "light, material, key, sphere, cube, cylinder, cone, torus, plane, disk, mesh, include or csg)");
    CHECK(message("inclued a.cfg").rfind("t.cfg:1:1: unknown statement 'inclued': did you mean 'include'? (", 0) == 0);
    // Nothing near: the list alone.
    CHECK(message("sphere bogus=1").rfind("t.cfg:1:8: unknown key 'bogus' for 'sphere' (expected one of: ", 0) == 0);
    CHECK(message("foo 1").rfind("t.cfg:1:1: unknown statement 'foo' (expected image, ", 0) == 0);
}

TEST_CASE("parser: errors carry the exact line and column") {
    SUBCASE("statement words") {
        expect_error("foo 1", 1, 1, "unknown statement 'foo'");
        expect_error("# c\n\n   spheres\n", 3, 4, "unknown statement 'spheres'");
        expect_error("ambient=0.1", 1, 1, "unknown statement");
        expect_error("light", 1, 1, "light kind");
        expect_error("light lamp pos=0,0,0", 1, 7, "got 'lamp'");
        expect_error("material", 1, 1, "material name");
        expect_error("material color=1,1,1", 1, 10, "material name");
        expect_error("ambient", 1, 1, "expected a number");
        expect_error("ambient 0.1 0.2", 1, 13, "unexpected '0.2'");
        expect_error("background", 1, 1, "colour");
        expect_error("include", 1, 1, "file path");
    }
    SUBCASE("keys") {
        expect_error("sphere bogus=1", 1, 8, "unknown key 'bogus' for 'sphere'");
        expect_error("sphere minor=0.3", 1, 8, "unknown key 'minor'");
        expect_error("light point pos=0,0,0 dir=0,1,0", 1, 23, "unknown key 'dir'");
        expect_error("light directional pos=0,0,0", 1, 19, "unknown key 'pos'");
        expect_error("image ambient=0.2", 1, 7, "unknown key 'ambient'");
        expect_error("camera eye=0,0,5 fov=40 zoom=2", 1, 25, "unknown key 'zoom'");
        expect_error("sphere color=1,1,1 color=1,1,1", 1, 20, "duplicate key 'color'");
        expect_error("sphere translate=1,0,0 translate=1,0,0", 1, 24, "duplicate key");
        expect_error("image width=10 width=20", 1, 16, "duplicate key 'width'");
        expect_error("sphere color", 1, 8, "missing '='");
        expect_error("cube  scale=1  rotate_y", 1, 16, "missing '='");
        expect_error("sphere =1", 1, 8, "missing key");
    }
    SUBCASE("values") {
        expect_error("image width=abc", 1, 13, "expected a number for 'width', got 'abc'");
        expect_error("image width=1.5x", 1, 13, "got '1.5x'");
        expect_error("image width=12.5", 1, 13, "integer");
        expect_error("image output=", 1, 14, "empty value for 'output'");
        expect_error("sphere color=", 1, 14, "empty value");
        expect_error("sphere color=1,1", 1, 14, "expected 3 comma-separated numbers");
        expect_error("sphere color=1,1,1,1", 1, 14, "got '1,1,1,1'");
        expect_error("sphere color=1,,1", 1, 14, "comma-separated");
        expect_error("sphere color=1, 1,1", 1, 17, "missing '='");  // no spaces inside a value
        expect_error("sphere color=1,x,1", 1, 14, "got '1,x,1'");
        expect_error("sphere diff=nan", 1, 13, "expected a number");
        expect_error("sphere diff=inf", 1, 13, "expected a number");
        expect_error("sphere diff=-inf", 1, 13, "expected a number");
        expect_error("sphere diff=1e999", 1, 13, "expected a number");
        expect_error("sphere diff=0x10", 1, 13, "expected a number");
        expect_error("sphere diff=++1", 1, 13, "expected a number");
        expect_error("ambient abc", 1, 9, "expected a number for 'ambient', got 'abc'");
        expect_error("background 1,1", 1, 12, "comma-separated");
        expect_error("image sampler=halton", 1, 15, "got 'halton'");
        expect_error("image calibration=gamma", 1, 19, "got 'gamma'");
        expect_error("image colorspace=rgb", 1, 18, "expected srgb or linear for 'colorspace', got 'rgb'");
        expect_error("image width=8 tonemap=aces", 1, 23, "expected clamp or reinhard for 'tonemap', got 'aces'");
        expect_error("image exr=int", 1, 11, "expected half or float for 'exr', got 'int'");
        expect_error("image exposure=0", 1, 16, "'exposure' must be a multiplier > 0, in [1e-6, 1e6], got '0'");
        expect_error("image exposure=-1", 1, 16, "got '-1'");
        expect_error("image exposure=1e7", 1, 16, "got '1e7'");
        expect_error("image exposure=9e-7", 1, 16, "got '9e-7'");
        expect_error("\nimage  exposure=bright", 2, 17, "expected a number for 'exposure', got 'bright'");
        expect_error("sphere rotate_x=ninety", 1, 17, "expected a number");
        expect_error("sphere scale=1,2", 1, 14, "comma-separated");
        expect_error("sphere scale=big", 1, 14, "expected a number or x,y,z");
    }
    SUBCASE("ranges") {
        expect_error("image width=0", 1, 13, "'width' must be in [1, 32768], got '0'");
        expect_error("image width=32769", 1, 13, "must be in [1, 32768]");
        expect_error("image height=0", 1, 14, "'height'");
        expect_error("image height=40000", 1, 14, "'height'");
        expect_error("image spp=0", 1, 11, "[1, 65536]");
        expect_error("image spp=65537", 1, 11, "[1, 65536]");
        expect_error("image depth=-1", 1, 13, "[0, 256]");
        expect_error("image depth=257", 1, 13, "[0, 256]");
        expect_error("image degree=7", 1, 14, "[0, 6]");
        expect_error("image degree=-1", 1, 14, "[0, 6]");
        expect_error("ambient 1.5", 1, 9, "[0, 1]");
        expect_error("ambient -0.1", 1, 9, "[0, 1]");
        expect_error("material m ior=0", 1, 16, "'ior' must be > 0");
        expect_error("sphere ior=-1.5", 1, 12, "'ior' must be > 0");
        expect_error("plane cell=0", 1, 12, "'cell' must be > 0");
        expect_error("light spot pos=0,5,0 dir=0,-1,0 angle=0", 1, 39, "'angle' must be in (0, 180)");
        expect_error("light spot pos=0,5,0 dir=0,-1,0 angle=180", 1, 39, "(0, 180)");
        expect_error("camera eye=0,0,5 fov=0", 1, 22, "'fov' must be in (0, 180)");
        expect_error("camera fov=180", 1, 12, "(0, 180)");
        expect_error("torus minor=0", 1, 13, "'minor' must be > 0");
        expect_error("torus minor=-0.2", 1, 13, "'minor' must be > 0");
        for (const char* k : {"ambi", "diff", "spec", "refl", "trans", "shininess"}) {
            const std::string text = std::string("sphere ") + k + "=-0.5";
            expect_error(text, 1, 9 + int(std::string(k).size()), "must be >= 0");
        }
        expect_error("sphere color=1,-0.1,1", 1, 14, "must be >= 0");
        expect_error("plane checker=-1,0,0", 1, 15, "must be >= 0");
        expect_error("background 0,0,-1", 1, 12, "must be >= 0");
        expect_error("light point pos=0,0,0 color=-1,1,1", 1, 29, "must be >= 0");
        // Colours are stored in single precision: 1e39 would become +inf (a fuzz finding).
        expect_error("sphere color=1,1e39,1", 1, 14, "at most 3.4e38");
        expect_error("light point pos=0,0,0 color=1e300,1,1", 1, 29, "at most 3.4e38");
        expect_error("plane checker=0,0,4e38", 1, 15, "at most 3.4e38");
        expect_error("camera rx=0", 1, 11, "'rx' must be > 0");
        expect_error("camera df=-1", 1, 11, "'df' must be > 0");
    }
    SUBCASE("transforms") {
        expect_error("sphere scale=0", 1, 14, "non-zero");
        expect_error("sphere scale=1,0,1", 1, 14, "non-zero");
        expect_error("cube translate=1,1,1 scale=-0", 1, 28, "non-zero");
        expect_error("camera scale=2,0,2", 1, 14, "non-zero");
        // A shear squashed flat: each factor is fine, the product is singular.
        expect_error("sphere\n  cube rotate_z=45 scale=1,1e13,1", 2, 3, "singular");
        expect_error("camera rotate_z=45 scale=1,1e13,1", 1, 1, "singular");
    }
    SUBCASE("camera forms") {
        expect_error("camera eye=0,0,5 rx=1", 1, 18, "'rx' belongs to the explicit form");
        expect_error("camera translate=0,0,5 look=0,0,0", 1, 24, "'look' belongs to the look-at form");
        expect_error("camera eye=1,1,1 look=1,1,1", 1, 1, "distinct");
        expect_error("camera eye=0,5,0 look=0,0,0 up=0,1,0", 1, 32, "parallel");
        expect_error("camera eye=0,5,0 look=0,0,0", 1, 1, "parallel");
        expect_error("camera up=0,0,0", 1, 11, "non-zero");
    }
    SUBCASE("lights") {
        expect_error("light point color=1,1,1", 1, 1, "needs 'pos");
        expect_error("light point", 1, 1, "needs 'pos");
        expect_error("light spot pos=0,1,0", 1, 1, "needs 'dir");
        expect_error("light spot dir=0,1,0", 1, 1, "needs 'pos");
        expect_error("light directional color=1,1,1", 1, 1, "needs 'dir");
        expect_error("light directional dir=0,0,0", 1, 23, "non-zero");
        expect_error("light spot pos=0,1,0 dir=0,0,0", 1, 26, "non-zero");
    }
    SUBCASE("materials") {
        expect_error("sphere material=glass", 1, 17, "unknown material 'glass'");
        expect_error("sphere material=glass\nmaterial glass trans=1\n", 1, 17, "defined before");
        expect_error("material a\nmaterial b material=c\n", 2, 21, "unknown material 'c'");
        expect_error("material a\nmaterial a diff=1\n", 2, 10, "already defined");
    }
    SUBCASE("a later line; key mistakes are reported before value mistakes") {
        expect_error("image width=10\n\n# x\nsphere color=1,1,1 spec=x\n", 4, 25, "'spec'");
        expect_error("image width=10\n\n# x\nsphere color=1,1,1 spec=x bogus=1\n", 4, 27, "'bogus'");
    }
}

TEST_CASE("parser: include, cycles, depth and missing files") {
    TempDir t;
    SUBCASE("include is relative to the including file") {
        t.write("sub/objects.cfg",
                "material gold color=1,0.8,0.2 refl=0.5\nsphere material=gold\n"
                "include deeper/light.cfg\n");
        t.write("sub/deeper/light.cfg", "light point pos=0,10,0\n");
        const fs::path top = t.write("top.cfg",
                                     "image width=100\ninclude sub/objects.cfg\n"
                                     "cube material=gold   # defined in the included file\n");
        const Scene s = load_scene(top.string());
        CHECK(s.path == top.string());
        REQUIRE(s.objects.size() == 2);
        REQUIRE(s.lights.size() == 1);
        CHECK(s.settings.width == 100);
        CHECK(s.material_of(s.objects[1]).refl == doctest::Approx(0.5));
        CHECK(s.where(0).file == (t.dir / "sub/objects.cfg").string());
        CHECK(s.where(0).line == 2);
        CHECK(s.where(1).file == top.string());
        CHECK(s.where(1).line == 3);
        // parse_scene resolves includes against the name's directory.
        const Scene m = parse_scene("include sub/objects.cfg\n", (t.dir / "mem.cfg").string());
        CHECK(m.objects.size() == 1);
        CHECK(m.lights.size() == 1);
    }
    SUBCASE("errors inside an included file name that file") {
        t.write("bad.cfg", "sphere\n\ncube diff=x\n");
        const fs::path top = t.write("top.cfg", "include bad.cfg\n");
        try {
            load_scene(top.string());
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.where().file == (t.dir / "bad.cfg").string());
            CHECK(e.where().line == 3);
            CHECK(e.where().column == 11);
        }
    }
    SUBCASE("missing included file") {
        const fs::path top = t.write("top.cfg", "sphere\n  include   nothere.cfg # gone\n");
        try {
            load_scene(top.string());
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.where().file == top.string());
            CHECK(e.where().line == 2);
            CHECK(e.where().column == 13);
            CHECK(e.message().find("cannot open included file") != std::string::npos);
        }
        // A directory is not a scene file either.
        fs::create_directories(t.dir / "adir");
        t.write("top2.cfg", "include adir\n");
        CHECK_THROWS_AS(load_scene((t.dir / "top2.cfg").string()), SceneError);
    }
    SUBCASE("include cycle") {
        const fs::path a = t.write("a.cfg", "sphere\ninclude b.cfg\n");
        t.write("b.cfg", "cube\n\ninclude ./a.cfg\n");
        try {
            load_scene(a.string());
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.where().file == (t.dir / "b.cfg").string());
            CHECK(e.where().line == 3);
            CHECK(e.where().column == 9);
            CHECK(e.message().find("include cycle") != std::string::npos);
        }
        const fs::path self = t.write("self.cfg", "include self.cfg\n");
        try {
            load_scene(self.string());
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.where().line == 1);
            CHECK(e.where().column == 9);
        }
        // Including the same file twice (no cycle) is fine.
        t.write("leaf.cfg", "sphere\n");
        const fs::path twice = t.write("twice.cfg", "include leaf.cfg\ninclude leaf.cfg\n");
        CHECK(load_scene(twice.string()).objects.size() == 2);
    }
    SUBCASE("nesting depth limit 32") {
        // f0 -> f1 -> ... -> f32 is 32 levels below the top and fine; one more fails.
        for (int i = 0; i < 33; ++i)
            t.write("f" + std::to_string(i) + ".cfg",
                    i < 32 ? "include f" + std::to_string(i + 1) + ".cfg\n" : "sphere\n");
        CHECK(load_scene((t.dir / "f0.cfg").string()).objects.size() == 1);
        t.write("f32.cfg", "include f33.cfg\n");
        t.write("f33.cfg", "sphere\n");
        try {
            load_scene((t.dir / "f0.cfg").string());
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.where().file == (t.dir / "f32.cfg").string());
            CHECK(e.where().line == 1);
            CHECK(e.where().column == 9);
            CHECK(e.message().find("32") != std::string::npos);
        }
    }
    SUBCASE("total file limit 1000") {
        // A binary tree of includes 10 deep reads 2^11 - 1 files without any cycle.
        for (int i = 0; i < 10; ++i)
            t.write("t" + std::to_string(i) + ".cfg", "include t" + std::to_string(i + 1) +
                                                          ".cfg\ninclude t" +
                                                          std::to_string(i + 1) + ".cfg\n");
        t.write("t10.cfg", "sphere\n");
        try {
            load_scene((t.dir / "t0.cfg").string());
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.message().find("1000") != std::string::npos);
            CHECK(e.where().column == 9);
        }
    }
    SUBCASE("missing top-level file") {
        const std::string p = (t.dir / "absent.cfg").string();
        try {
            load_scene(p);
            FAIL("expected a SceneError");
        } catch (const SceneError& e) {
            CHECK(e.where().file == p);
            CHECK(e.where().line == 0);
            CHECK(e.message() == "cannot open scene file");
        }
    }
}

TEST_CASE("parser: the reference statements all parse") {
    TempDir t;
    t.write("other.cfg", "light point pos=-5,8,5\n");
    const fs::path top = t.write("ref.cfg",
                                 "image width=640 height=480 spp=4 depth=5 degree=5 output=out.png\n"
                                 "ambient 0.1\n"
                                 "background 0.02,0.02,0.05\n"
                                 "camera eye=0,1,6 look=0,0.5,0 up=0,1,0 fov=45\n"
                                 "camera rx=1 ry=0.75 df=2 rotate_x=-10 translate=0,1,6\n"
                                 "light point pos=5,8,5 color=1,1,1\n"
                                 "light spot pos=0,5,0 dir=0,-1,0 angle=30\n"
                                 "light directional dir=-1,-1,-1 color=0.5,0.5,0.5\n"
                                 "material glass color=1,1,1 ambi=0 diff=0 refl=0.1 trans=0.9 ior=1.5\n"
                                 "sphere material=glass scale=1 translate=0,1,0\n"
                                 "cube color=1,0,0 ambi=0.2 diff=0.8 scale=0.5,1,0.5 rotate_y=45 translate=2,0.5,0\n"
                                 "torus minor=0.25 color=0.9,0.7,0.2 diff=0.8 rotate_x=90 translate=-2,1,0\n"
                                 "cylinder color=0.2,0.8,0.3 diff=0.8 scale=0.5,1,0.5\n"
                                 "cone color=0.3,0.3,0.9 diff=0.8 translate=0,1,-3\n"
                                 "plane color=0.8,0.8,0.8 checker=0.2,0.2,0.2 cell=1 diff=0.9\n"
                                 "include other.cfg\n");
    const Scene s = load_scene(top.string());
    CHECK(s.objects.size() == 6);
    CHECK(s.lights.size() == 4);
    CHECK_FALSE(s.camera.look_at);
    CHECK(s.settings.spp == 4);
}

TEST_CASE("parser: every scene under scenes/ loads") {
    const fs::path root = fs::path(STREAMRT_SOURCE_DIR) / "scenes";
    REQUIRE(fs::is_directory(root));
    int count = 0;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
        if (!entry.is_regular_file() || entry.path().extension() != ".cfg") continue;
        ++count;
        INFO("scene: ", entry.path().string());
        Scene s;
        try {
            s = load_scene(entry.path().string());
        } catch (const SceneError& e) {
            FAIL_CHECK(e.what());
        }
        CHECK(s.objects.size() > 0);
        // Something lights it: a light, or at degree 6 the sky or an emitting surface.
        const bool sky = s.settings.background != glm::dvec3(0.0);
        const bool emits = std::any_of(s.materials.begin(), s.materials.end(),
                                       [](const Material& m) { return m.emission != glm::dvec3(0.0); });
        CHECK((s.lights.size() > 0 || (s.settings.degree == 6 && (sky || emits))));
    }
    CHECK(count >= 10);
}

TEST_CASE("parser: the example in docs/scene-format.md parses") {
    std::ifstream in(fs::path(STREAMRT_SOURCE_DIR) / "docs" / "scene-format.md");
    REQUIRE(in);
    std::string line, text;
    bool in_section = false, in_block = false, done = false;
    while (!done && std::getline(in, line)) {
        if (line.rfind("## A complete example", 0) == 0) in_section = true;
        else if (in_section && line.rfind("```", 0) == 0) {
            if (in_block) done = true;
            in_block = true;
        } else if (in_block) {
            text += line + "\n";
        }
    }
    REQUIRE(done);
    const Scene s = parse_scene(text, "example.cfg");
    CHECK(s.objects.size() == 4);
    CHECK(s.lights.size() == 2);
    CHECK(s.camera.look_at);
    CHECK(s.settings.output == "example.png");
}

TEST_CASE("parser: disk statements (shapes/shapes.h registry), keys and errors at file:line:col") {
    const Scene s = parse(
        "material shiny refl=0.5\n"
        "disk color=0.2,0.4,0.6 diff=0.7 scale=2 rotate_x=90 translate=0,1,0\n"
        "  disk material=shiny\n");
    REQUIRE(s.objects.size() == 2);
    CHECK(s.objects[0].kind == ShapeKind::Disk);
    CHECK(s.objects[0].param == 0.0);
    CHECK(s.objects[1].kind == ShapeKind::Disk);
    CHECK(s.where(1).line == 3);
    CHECK(s.where(1).column == 3);
    CHECK(s.material_of(s.objects[1]).refl == doctest::Approx(0.5));
    // The canonical point (1, 0, 0) -> scale 2 -> rotate_x 90 (unchanged) -> (2, 1, 0).
    const glm::dvec3 p = glm::dvec3(s.objects[0].direct() * glm::dvec4(1, 0, 0, 1));
    CHECK(p.x == doctest::Approx(2.0));
    CHECK(p.y == doctest::Approx(1.0));

    expect_error("disk\ndisk minor=0.3", 2, 6, "unknown key 'minor' for 'disk'");
    expect_error("disk radius=2", 1, 6, "unknown key 'radius'");
    expect_error("disks", 1, 1, "torus, plane, disk, mesh, include or csg");
    // The torus keeps its parameter key, default and check, now declared by TorusMath.
    CHECK(parse("torus").objects[0].param == doctest::Approx(0.25));
    CHECK(parse("torus minor=0.4").objects[0].param == doctest::Approx(0.4));
    expect_error("torus minor=0", 1, 13, "'minor' must be > 0");
}

TEST_CASE("parser: a scene beyond the object limit is refused at the first object past it") {
    // The stream engine carries object numbers in float lanes, exact to 2^24 (kMaxSceneObjects);
    // the check takes its limit as an argument so that a three-object scene can stand in.
    const Scene s = parse("sphere\n\n  cube scale=2\nplane\n");
    s.check_object_count();  // far below the real limit
    s.check_object_count(3);
    bool thrown = false;
    try {
        s.check_object_count(2);
    } catch (const SceneError& e) {
        thrown = true;
        CHECK(e.where().file == "t.cfg");
        CHECK(e.where().line == 4);  // the third object: `plane`
        CHECK(e.where().column == 1);
        CHECK(e.message() == "the scene holds 3 objects, more than the 2 streamrt supports; this is object 3");
    }
    CHECK(thrown);
    thrown = false;
    try {
        s.check_object_count(1);
    } catch (const SceneError& e) {
        thrown = true;
        CHECK(e.where().line == 3);  // `cube`, indented by two
        CHECK(e.where().column == 3);
    }
    CHECK(thrown);
    CHECK(kMaxSceneObjects == 16777216);
}
