// Animation (scene/animation.h): name= and key statements read into tracks, interpolated at a
// frame to the matrices and values worked out by hand here, and every bad value reported at
// its exact line and column.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "scene/animation.h"
#include "scene/expect_error.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

Scene parse(const std::string& text) { return parse_scene(text, "t.cfg"); }

using test::expect_error;

/// Column c of the object's Md (linear part: the image of an axis; column 3: translation).
glm::dvec3 column(const Scene& s, std::size_t object, int c) { return s.objects[object].md[c]; }

bool near(const glm::dvec3& a, const glm::dvec3& b, double eps = 1e-12) { return glm::length(a - b) <= eps; }

}  // namespace

TEST_CASE("animation: a scene without keys has no animation, names alone allocate nothing") {
    CHECK(parse("sphere\n").animation == nullptr);
    const Scene s = parse("sphere name=a\nlight point name=l pos=1,2,3\ncamera name=c eye=0,0,5 look=0,0,0\n");
    CHECK(s.animation == nullptr);
    CHECK(!s.settings.has_frames());
}

TEST_CASE("animation: translate halfway between two keys, composed after the statement's transform") {
    // Md(f) = T(key) Md_statement; Md_statement = T(1,0,0) S(0.5).
    const std::string text =
        "sphere name=a scale=0.5 translate=1,0,0\n"
        "key a frame=0 translate=0,0,0\n"
        "key a frame=4 translate=2,4,-6\n";
    Scene s = parse(text);
    REQUIRE(s.animation != nullptr);
    // The scene as read is at frame 0.
    CHECK(near(column(s, 0, 3), {1, 0, 0}));
    set_frame(s, 1);  // a quarter of the way: (0.5, 1, -1.5) added
    CHECK(near(column(s, 0, 3), {1.5, 1, -1.5}));
    CHECK(near(column(s, 0, 0), {0.5, 0, 0}));  // the scale untouched
    set_frame(s, 2);
    CHECK(near(column(s, 0, 3), {2, 2, -3}));
    // Outside the keyed range the last / first key holds.
    set_frame(s, 100);
    CHECK(near(column(s, 0, 3), {3, 4, -6}));
    set_frame(s, 0);
    CHECK(near(column(s, 0, 3), {1, 0, 0}));
}

TEST_CASE("animation: rotation halfway, by the shortest arc") {
    const double h = std::sqrt(0.5);
    SUBCASE("90 degrees about z, halfway: 45 degrees") {
        Scene s = parse("cube name=a\nkey a frame=0 rotate=0,0,1,0\nkey a frame=2 rotate=0,0,1,90\n");
        set_frame(s, 1);
        // Rz(45): x -> (c, s, 0), y -> (-s, c, 0).
        CHECK(near(column(s, 0, 0), {h, h, 0}));
        CHECK(near(column(s, 0, 1), {-h, h, 0}));
        CHECK(near(column(s, 0, 2), {0, 0, 1}));
        set_frame(s, 2);
        CHECK(near(column(s, 0, 0), {0, 1, 0}));
    }
    SUBCASE("350 to 10 degrees goes through 0, not through 180") {
        Scene s = parse("cube name=a\nkey a frame=0 rotate=0,0,1,350\nkey a frame=4 rotate=0,0,1,10\n");
        set_frame(s, 2);
        CHECK(near(column(s, 0, 0), {1, 0, 0}));
        CHECK(near(column(s, 0, 1), {0, 1, 0}));
        set_frame(s, 1);  // a quarter of the 20-degree arc: 355 = -5 degrees
        const double a = -5.0 * 3.14159265358979323846 / 180.0;
        CHECK(near(column(s, 0, 0), {std::cos(a), std::sin(a), 0}));
    }
    SUBCASE("T R S order: scale, then rotate, then translate, after the statement") {
        // Md = T(1,2,3) Rz(90) S(2,1,1) S(0.5): x -> Rz(90) (1,0,0) = (0,1,0),
        // y -> Rz(90) (0,0.5,0) = (-0.5,0,0), z -> (0,0,0.5); the statement's translation
        // (0,0,1) goes through the keys too: T Rz S (0,0,1) = (1,2,4).
        Scene s = parse("sphere name=a scale=0.5 translate=0,0,1\n"
                        "key a frame=0 translate=1,2,3 rotate=0,0,1,90 scale=2,1,1\n");
        CHECK(near(column(s, 0, 0), {0, 1, 0}));
        CHECK(near(column(s, 0, 1), {-0.5, 0, 0}));
        CHECK(near(column(s, 0, 2), {0, 0, 0.5}));
        CHECK(near(column(s, 0, 3), {1, 2, 4}));
    }
}

TEST_CASE("animation: each quantity is its own track, lights and the camera") {
    const std::string text =
        "camera name=cam eye=0,0,5 look=0,0,0 fov=40\n"
        "light point name=l pos=0,5,0 color=1,1,1\n"
        "light point pos=9,9,9\n"
        "sphere name=a\n"
        "sphere\n"
        "key a frame=0 translate=0,0,0\n"
        "key a frame=10 translate=10,0,0\n"
        "key a frame=4 scale=1\n"
        "key a frame=8 scale=3\n"
        "key l frame=2 pos=0,4,0 color=0,0,0\n"
        "key l frame=6 pos=4,4,0 color=1,0.5,0\n"
        "key cam frame=0 eye=0,0,5 fov=40\n"
        "key cam frame=10 eye=10,0,5 fov=60\n";
    Scene s = parse(text);
    const FrameChange c = set_frame(s, 5);
    // translate at 5: (5,0,0); scale between 4 (1) and 8 (3) at 5: 1.5.
    CHECK(near(column(s, 0, 3), {5, 0, 0}));
    CHECK(near(column(s, 0, 0), {1.5, 0, 0}));
    CHECK(near(s.lights[0].pos, {3, 4, 0}));
    CHECK(near(s.lights[0].color, {0.75, 0.375, 0}));
    CHECK(near(s.lights[1].pos, {9, 9, 9}));  // not named, not keyed
    CHECK(near(s.camera.eye, {5, 0, 5}));
    CHECK(s.camera.fov == doctest::Approx(50.0).epsilon(1e-15));
    // Only the keyed object moved.
    REQUIRE(c.objects.size() == 1);
    CHECK(c.objects[0] == 0);
    CHECK(c.lights);
    CHECK(c.camera);
    // Past every key nothing changes any more.
    set_frame(s, 10);
    const FrameChange held = set_frame(s, 11);
    CHECK(!held.any());
}

TEST_CASE("animation: image frames= and the frame range") {
    const Scene s = parse("image frames=2..30\n");
    CHECK(s.settings.frames_first == 2);
    CHECK(s.settings.frames_last == 30);
    const Scene one = parse("image frames=7\n");
    CHECK(one.settings.frames_first == 7);
    CHECK(one.settings.frames_last == 7);
    int a = 0, b = 0;
    std::string why;
    CHECK(!parse_frame_range("10..2", a, b, why));
    CHECK(why.find("backwards") != std::string::npos);
    CHECK(!parse_frame_range("-1..2", a, b, why));
    CHECK(!parse_frame_range("1.5..2", a, b, why));
    CHECK(!parse_frame_range("1..", a, b, why));
}

TEST_CASE("animation: bad names and keys at their line:col") {
    // The frame range.
    expect_error("image frames=10..2\n", 1, 14, "runs backwards");
    expect_error("image frames=-1..2\n", 1, 14, "integer >= 0");
    expect_error("image frames=a\n", 1, 14, "integer >= 0");
    // Names.
    expect_error("sphere name=1a\n", 1, 13, "a name starts with a letter");
    expect_error("sphere name=a\ncube name=a\n", 2, 11, "name 'a' is already given to the object of line 1");
    expect_error("sphere name=a\nlight point pos=0,1,0 name=a\n", 2, 28, "already given");
    expect_error("camera name=a eye=0,0,5 look=0,0,0\nsphere name=a\n", 2, 13, "already given to the camera");
    // Keys.
    expect_error("sphere name=a\nkey b frame=1 translate=1,2,3\n", 2, 5, "key for an unknown name 'b'");
    expect_error("key\n", 1, 1, "expected a name after 'key'");
    expect_error("sphere name=a\nkey a frame=1 eye=1,2,3\n", 2, 15, "'eye' does not fit the object 'a'");
    expect_error("light point name=l pos=0,1,0\nkey l frame=1 translate=1,2,3\n", 2, 15,
                 "'translate' does not fit the light 'l'");
    expect_error("camera name=c eye=0,0,5 look=0,0,0\nkey c frame=1 pos=1,2,3\n", 2, 15,
                 "'pos' does not fit the camera 'c'");
    expect_error("light directional name=s dir=0,-1,0\nkey s frame=0 pos=1,2,3\n", 2, 15, "directional");
    expect_error("camera name=c translate=0,0,5\nkey c frame=0 eye=1,2,3\n", 2, 5, "look-at form");
    expect_error("sphere name=a\nkey a translate=1,2,3\n", 2, 1, "key needs 'frame=F'");
    expect_error("sphere name=a\nkey a frame=-1 translate=1,2,3\n", 2, 13, "'frame' must be in [0, 1000000]");
    expect_error("sphere name=a\nkey a frame=1.5 translate=1,2,3\n", 2, 13, "expected an integer for 'frame'");
    expect_error("sphere name=a\nkey a frame=2\n", 2, 1, "nothing keyed");
    expect_error("sphere name=a\nkey a frame=1 translate=1,2,3\nkey a frame=1 scale=2\n", 3, 13,
                 "already has a key at frame 1 (line 2)");
    expect_error("sphere name=a\nkey a frame=1 rotate=0,0,0,90\n", 2, 22, "non-zero vector");
    expect_error("sphere name=a\nkey a frame=1 rotate=0,0,90\n", 2, 22, "ax,ay,az,degrees");
    expect_error("sphere name=a\nkey a frame=1 scale=-1\n", 2, 21, "must be > 0");
    expect_error("sphere name=a\nkey a frame=1 translate=1,2,3 translate=1,2,3\n", 2, 31, "duplicate key");
    expect_error("sphere name=a\nkey a frame=0 translate=1e308,0,0 scale=1e-300\n", 2, 1,
                 "transform at frame 0 is singular or not finite");
    expect_error("camera name=c eye=0,0,5 look=0,0,0\nkey c frame=3 eye=0,0,0\n", 2, 1,
                 "at frame 3 the camera's eye and look coincide");
    // A key names what is defined above it (the file is read in order).
    expect_error("key a frame=1 translate=1,2,3\nsphere name=a\n", 1, 5, "unknown name");
}

TEST_CASE("animation: the chunked reader checks names across chunks and reads keys in order") {
    std::string text;
    for (int i = 0; i < 200; ++i) text += "sphere name=s" + std::to_string(i) + " translate=" + std::to_string(i) + ",0,0\n";
    ReadOptions chunked;
    chunked.chunked_from = 1;
    chunked.chunk_bytes = 256;
    chunked.jobs = 2;
    // With a key statement the text is read in one pass (keys need the objects above them).
    Scene s = parse_scene(text + "key s199 frame=4 translate=0,1,0\n", "t.cfg", chunked);
    REQUIRE(s.objects.size() == 200);
    set_frame(s, 4);
    CHECK(near(column(s, 199, 3), {199, 1, 0}));
    // Names only: read in parallel chunks; a duplicate in another chunk is refused at its line.
    bool thrown = false;
    try {
        parse_scene(text + "cube name=s3\n", "t.cfg", chunked);
    } catch (const SceneError& e) {
        thrown = true;
        CHECK(e.where().line == 201);
        CHECK(e.where().column == 11);
    }
    CHECK(thrown);
}
