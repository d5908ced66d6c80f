// CSG at its numerically hard places (issue 49, "Numerics"; docs/scene-format.md, "CSG",
// "Where surfaces coincide"): coinciding faces, a line tangent to a child, a line through the
// rim where two children meet, and the lens at the stability suite's scales and offsets. The
// expected values are worked out by hand from the shapes' definitions.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "baseline/recursive_renderer.h"
#include "render/csg_cases.h"
#include "scene/parser.h"

using namespace streamrt;
using csg_cases::hit_of;

namespace {


Scene parse(const std::string& text) { return parse_scene(text, "t.cfg"); }


/// Which of the CSG object's shapes (in written order) a hit is on.
std::size_t csg_shape_of(const Scene& s, const HitD& hit) { return std::size_t(hit.object) - s.objects.size(); }

}  // namespace

TEST_CASE("csg numerics: a subtracted face lying on the base's face removes it") {
    // The cube [-1,1]^3 minus the box [-0.5,0.5]^2 x [0,1] (a cube of half-size 0.5 centred at
    // z = 0.5): the two share the plane z = 1. The line down the axis enters both at z = 1 at
    // once; the point after it is in both, so out of the result: no surface there. The first
    // surface is the pocket's floor z = 0, the subtracted box's face, turned to face +z.
    const Scene s = parse("csg difference\n  cube\n  cube scale=0.5 translate=0,0,0.5\nend\n");
    HitD hit;
    REQUIRE(hit_of(s, {0, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == 5.0);
    CHECK(hit.normal.z == doctest::Approx(1.0));
    CHECK(csg_shape_of(s, hit) == 1);
    // Beside the pocket the base's face is there.
    REQUIRE(hit_of(s, {0.8, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == 4.0);
    CHECK(csg_shape_of(s, hit) == 0);
    // Along the pocket's side wall's plane x = 0.5 from above: the wall is a face of the removed
    // box seen edge-on; the line runs in the pocket's boundary, so what it meets is the base's
    // material below the pocket, z = 0 (the box's floor edge) at the latest.
    REQUIRE(hit_of(s, {0.5, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t >= 4.0);
    CHECK(hit.t <= 5.0);
}

TEST_CASE("csg numerics: where an intersection's children enter together, the first child's face is shown") {
    // [-1,1]^3 and the same cube moved by 1 along z: both have the faces x = +-1 and y = +-1.
    // Along -x at z = 0.5 both enter at x = 1 at the same t: the result is entered there, on
    // both faces at once; the first-written child's is the one shown.
    const Scene s = parse("csg intersection\n  cube\n  cube translate=0,0,1\nend\n");
    HitD hit;
    REQUIRE(hit_of(s, {5, 0, 0.5}, {-1, 0, 0}, hit));
    CHECK(hit.t == 4.0);
    CHECK(hit.normal.x == doctest::Approx(1.0));
    CHECK(csg_shape_of(s, hit) == 0);
    // The result is [-1,1]^2 x [0,1]: the line along -z meets its top z = 1 (the first cube's
    // face; the second's top is at z = 2) and leaves at z = 0 (the second cube's bottom).
    REQUIRE(hit_of(s, {0, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == 4.0);
    CHECK(csg_shape_of(s, hit) == 0);
    REQUIRE(hit_of(s, {0, 0, 5}, {0, 0, -1}, hit, 4.0 + 1e-9));
    CHECK(hit.t == 5.0);
    CHECK(csg_shape_of(s, hit) == 1);
}

TEST_CASE("csg numerics: a line tangent to a subtracted sphere passes it") {
    // The cube minus a hidden cavity, the sphere of radius 0.5 at the centre. The line x = 0.5,
    // y = 0 along -z touches the sphere at (0.5, 0, 0): the discriminant is exactly 0 in double
    // (|o|^2 - r^2 = 25.25 - 0.25 = 25 = (o.d)^2), the sphere's span has length 0 and bounds
    // nothing. The line enters the cube at z = 1 and leaves it at z = -1, and nothing between.
    const Scene s = parse("csg difference\n  cube\n  sphere scale=0.5\nend\n");
    HitD hit;
    REQUIRE(hit_of(s, {0.5, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == 4.0);
    REQUIRE(hit_of(s, {0.5, 0, 5}, {0, 0, -1}, hit, 4.0 + 1e-9));
    CHECK(hit.t == 6.0);
    CHECK(csg_shape_of(s, hit) == 0);
    // A hair inside the tangent the cavity is there, its wall near z = 0 and facing into it.
    REQUIRE(hit_of(s, {0.4999, 0, 5}, {0, 0, -1}, hit, 4.0 + 1e-9));
    CHECK(csg_shape_of(s, hit) == 1);
    CHECK(hit.t == doctest::Approx(5.0 - std::sqrt(0.25 - 0.4999 * 0.4999)).epsilon(1e-12));
    CHECK(hit.normal.z < 0.0);  // the cavity's upper wall, seen from the material above it, faces down
}

TEST_CASE("csg numerics: a line through a lens's rim meets it only inside the rim") {
    // Spheres of radius 2 at z = -1.5 and z = +1.5 meet on the circle x^2 + y^2 = 1.75, z = 0.
    // Inside it by a relative 1e-6 the lens is a sliver around z = 0, its faces at
    // z = +-(sqrt(4 - x^2) - 1.5) = +-1.1667e-6; outside it by as much there is nothing.
    const Scene s = parse("csg intersection\n  sphere scale=2 translate=0,0,-1.5\n"
                          "  sphere scale=2 translate=0,0,1.5\nend\n");
    const double rim = std::sqrt(1.75);
    HitD hit;
    const double x_in = rim * (1 - 1e-6);
    const double z = std::sqrt(4 - x_in * x_in) - 1.5;
    CHECK(z == doctest::Approx(1.1667e-6).epsilon(1e-3));
    REQUIRE(hit_of(s, {x_in, 0, 5}, {0, 0, -1}, hit));
    CHECK(hit.point.z == doctest::Approx(z).epsilon(1e-6));
    REQUIRE(hit_of(s, {x_in, 0, 5}, {0, 0, -1}, hit, hit.t + 1e-9));
    CHECK(hit.point.z == doctest::Approx(-z).epsilon(1e-6));
    CHECK(!hit_of(s, {rim * (1 + 1e-6), 0, 5}, {0, 0, -1}, hit));
}

TEST_CASE("csg numerics: the lens at the stability suite's scales and offsets") {
    // The lens scaled by k and moved by (o, 0, 0): along the axis its caps are at z = +-0.5 k,
    // met at t = 10 k -+ 0.5 k from z = 10 k. Relative error: a few ulps of the offset's size.
    for (const auto& [k, o] : {std::pair{1e-4, 0.0}, {1.0, 0.0}, {1e5, 0.0}, {1.0, 1e6}, {1e5, 1e6}}) {
        CAPTURE(k);
        CAPTURE(o);
        const std::string t = "csg intersection scale=" + std::to_string(k) + " translate=" + std::to_string(o) +
                              ",0,0\n  sphere scale=2 translate=0,0,-1.5\n  sphere scale=2 translate=0,0,1.5\nend\n";
        const Scene s = parse(t);
        const double tol = 1e-12 * std::max(1.0, o / k);
        HitD hit;
        REQUIRE(hit_of(s, {o, 0, 10 * k}, {0, 0, -1}, hit));
        CHECK(hit.t / k == doctest::Approx(9.5).epsilon(tol));
        CHECK(hit.normal.z == doctest::Approx(1.0).epsilon(1e-9));
        REQUIRE(hit_of(s, {o, 0, 10 * k}, {0, 0, -1}, hit, hit.t * (1 + 1e-9)));
        CHECK(hit.t / k == doctest::Approx(10.5).epsilon(tol));
        CHECK(hit.normal.z == doctest::Approx(-1.0).epsilon(1e-9));
        // Off the axis at x = 0.5 k: the caps where the spheres say, z = +-(sqrt(3.75) - 1.5) k.
        const double zc = std::sqrt(3.75) - 1.5;
        REQUIRE(hit_of(s, {o + 0.5 * k, 0, 10 * k}, {0, 0, -1}, hit));
        CHECK(hit.t / k == doctest::Approx(10 - zc).epsilon(std::max(tol, 1e-9)));
    }
}
