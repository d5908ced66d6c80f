// One-pixel scenes whose colour is known in closed form, at every degree, through both
// engines. The camera at (0,0,5) looks at a unit sphere; the centre ray hits (0,0,1) with
// normal (0,0,1).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "driver/render.h"
#include "render/one_pixel.h"
#include "render/shading.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

const std::string kHead =
    "image width=1 height=1 spp=1 depth=3\n"
    "camera eye=0,0,5 look=0,0,0 up=0,1,0 fov=10\n"
    "ambient 0.1\n"
    "background 0.2,0.3,0.4\n";

void check_pixel(const std::string& body, int degree, double r, double g, double b) {
    test::check_one_pixel(parse_scene(kHead + "image degree=" + std::to_string(degree) + "\n" + body, "pixel.cfg"), r,
                          g, b);
}

}  // namespace

// "image degree=" may only appear once per statement, but a second image statement overrides.
TEST_CASE("degree 0: the flat colour") {
    check_pixel("sphere color=0.8,0.4,0.2\nlight point pos=0,0,10\n", 0, 0.8, 0.4, 0.2);
}

TEST_CASE("miss: the background") {
    check_pixel("sphere color=0.8,0.4,0.2 translate=10,0,0\nlight point pos=0,0,10\n", 2, 0.2, 0.3, 0.4);
}

TEST_CASE("degree 1: Lambert with white light plus the ambient fraction") {
    // Light straight above the hit point: N.w = 1, light colour ignored at degree 1.
    check_pixel("sphere color=0.8,0.4,0.2\nlight point pos=0,0,10 color=0.5,0.5,0.5\n", 1, 0.88, 0.44, 0.22);
    // At 45 degrees: N.w = 1/sqrt(2).
    const double k = 1 / std::sqrt(2.0) + 0.1;
    check_pixel("sphere color=0.8,0.4,0.2\nlight point pos=0,4,5\n", 1, 0.8 * k, 0.4 * k, 0.2 * k);
    // Behind the surface: ambient only.
    check_pixel("sphere color=0.8,0.4,0.2\nlight point pos=0,0,-10\n", 1, 0.08, 0.04, 0.02);
}

TEST_CASE("degree 2: material weights and light colour") {
    // 0.5 (light) * 0.6 (diff) * 1 (N.w) + 0.1 (alpha) * 0.5 (ambi) = 0.35 of the colour.
    check_pixel("sphere color=0.8,0.4,0.2 ambi=0.5 diff=0.6\nlight point pos=0,0,10 color=0.5,0.5,0.5\n", 2,
                0.8 * 0.35, 0.4 * 0.35, 0.2 * 0.35);
    // Two lights add; a directional light shining along -z.
    check_pixel("sphere color=1,1,1 ambi=0 diff=1\nlight point pos=0,0,10 color=0.25,0,0\n"
                "light directional dir=0,0,-1 color=0,0.5,0\n", 2, 0.25, 0.5, 0.0);
    // Spot: inside its cone lights, outside does not.
    check_pixel("sphere color=1,1,1 ambi=0 diff=1\nlight spot pos=0,0,10 dir=0,0,-1 angle=10\n", 2, 1, 1, 1);
    check_pixel("sphere color=1,1,1 ambi=0 diff=1\nlight spot pos=0,0,10 dir=0,1,-1 angle=10\n", 2, 0, 0, 0);
    // Phong: the mirrored light direction is the view direction, (R.V)^n = 1.
    check_pixel("sphere color=1,1,1 ambi=0 diff=0 spec=0.5 shininess=10\nlight point pos=0,0,10\n", 2, 0.5, 0.5, 0.5);
}

TEST_CASE("degree 3: a mirror brings back what the reflected ray sees") {
    // The reflected ray goes back along +z and meets nothing: local + refl * background.
    check_pixel("sphere color=1,1,1 ambi=0 diff=0 refl=0.5\nlight point pos=0,0,10\n", 3, 0.1, 0.15, 0.2);
    // A white emitter-like sphere behind the camera is seen in the mirror: flat-lit by ambi 1.
    check_pixel("sphere color=1,1,1 ambi=0 diff=0 refl=0.5\nsphere color=0,1,0 ambi=1 diff=0 translate=0,0,20\n"
                "light point pos=0,-10,0\n", 3, 0.0, 0.05, 0.0);
    // Below degree 3 the mirror term is ignored.
    check_pixel("sphere color=1,1,1 ambi=0 diff=0 refl=0.5\nlight point pos=0,0,10\n", 2, 0, 0, 0);
}

TEST_CASE("degree 4: straight through a glass sphere at normal incidence, and depth limits it") {
    // Enters at (0,0,1), leaves at (0,0,-1) undeviated, reaches the background: trans^2 * bg.
    check_pixel("sphere color=1,1,1 ambi=0 diff=0 trans=0.5 ior=1.5\nlight point pos=0,10,0\n", 4,
                0.25 * 0.2, 0.25 * 0.3, 0.25 * 0.4);
    // With depth 1 the ray inside cannot spawn again: only the entry's share of an unlit inside.
    const Scene s = parse_scene(kHead + "image degree=4 depth=1\nsphere color=1,1,1 ambi=0 diff=0 trans=0.5 ior=1.5\n"
                                        "light point pos=0,10,0\n", "d1.cfg");
    for (EngineKind e : {EngineKind::Recursive, EngineKind::Stream}) {
        Parallelism par(1);
        CHECK(render_scene(s, e, par).image.pixel(0, 0)[2] == doctest::Approx(0.0));
    }
}

TEST_CASE("degree 5: a shadow ray blocked by another object removes the direct light") {
    const std::string scene = "sphere color=0.8,0.4,0.2\nlight point pos=0,0,10\nsphere scale=0.1 translate=0,0,5.5\n";
    check_pixel(scene, 4, 0.88, 0.44, 0.22);  // no shadow rays below degree 5 (white light: 1 + 0.1)
    check_pixel(scene, 5, 0.08, 0.04, 0.02);  // ambient only
    // An occluder beyond the light does not block it.
    check_pixel("sphere color=0.8,0.4,0.2\nlight point pos=0,0,10\nsphere scale=0.1 translate=0,0,12\n", 5, 0.88,
                0.44, 0.22);
}

TEST_CASE("Snell's law and total internal reflection") {
    const double s45 = std::sqrt(0.5);
    const Vec3d n{0, 1, 0};
    // Entering glass (ior 1.5) at 45 degrees: sin(t) = sin(45) / 1.5.
    bool tir = true;
    const Vec3d t = refract(Vec3d{s45, -s45, 0}, n, 1.5, &tir);
    CHECK_FALSE(tir);
    CHECK(t.x == doctest::Approx(s45 / 1.5));
    CHECK(t.y == doctest::Approx(-std::sqrt(1 - 0.5 / 2.25)));
    // Leaving glass: the critical angle is asin(1/1.5) = 41.81 degrees.
    const double crit = std::asin(1 / 1.5);
    const double below = crit - 1e-3, above = crit + 1e-3;
    refract(Vec3d{std::sin(below), std::cos(below), 0}, n, 1.5, &tir);
    CHECK_FALSE(tir);
    const Vec3d r = refract(Vec3d{std::sin(above), std::cos(above), 0}, n, 1.5, &tir);
    CHECK(tir);
    CHECK(r.x == doctest::Approx(std::sin(above)));
    CHECK(r.y == doctest::Approx(-std::cos(above)));  // mirrored back inside
    // Normal incidence goes straight through.
    const Vec3d s = refract(Vec3d{0, -1, 0}, n, 2.42, &tir);
    CHECK(s.y == doctest::Approx(-1.0));
}

TEST_CASE("ray origin offset scales with the magnitude of the point and of the ray origin, seen from the eye") {
    const Vec3f n{0, 1, 0};
    const Vec3f world_origin{0.f, 0.f, 0.f};
    for (float scale : {1e-4f, 1.f, 1e5f, 1e6f}) {
        CAPTURE(scale);
        const Vec3f p{scale, 0.f, scale};  // on a y = 0 floor
        const Vec3f from{0.f, scale, 3 * scale};
        const Vec3f q = offset_ray_origin(p, n, from, world_origin);
        CHECK(q.y > p.y);
        CHECK(q.x == p.x);
        // Scale-free: the same fraction of the scene at every scale, and at most a few
        // hundred ulps of the largest coordinate (never a fixed epsilon).
        CHECK((q.y - p.y) / (3 * scale) == doctest::Approx(1.0 / 131072));
        // The same step in double: both engines render the same picture.
        const Vec3d qd = offset_ray_origin(Vec3d{scale, 0, scale}, Vec3d{0, 1, 0}, Vec3d{0, scale, 3.0 * scale},
                                           Vec3d{0, 0, 0});
        CHECK(qd.y / (3.0 * scale) == doctest::Approx(1.0 / 131072));
    }
    // Measured from the eye: the scene and its eye moved 1000 units away keep their step
    // (the stream engine renders relative to the eye; the recursive engine passes it).
    const Vec3d shift{1000, -2000, 500};
    const Vec3d p{1, 0, 1}, from{0, 1, 3}, eye{0, 1, 3};
    const Vec3d near = offset_ray_origin(p, Vec3d{0, 1, 0}, from, eye);
    const Vec3d far = offset_ray_origin(p + shift, Vec3d{0, 1, 0}, from + shift, eye + shift);
    CHECK(near.y - p.y == doctest::Approx(2.0 / 131072));  // p - eye = (1, -1, -2), from = eye
    CHECK(far.y - (p + shift).y == doctest::Approx(near.y - p.y).epsilon(1e-6));
    // A point at the exact origin still moves.
    CHECK(offset_ray_origin(Vec3f{0, 0, 0}, n, Vec3f{0, 0, 0}, Vec3f{0, 0, 0}).y > 0.f);
}
