// Hand-computed hits and normals for every canonical shape (scalar double, as the baseline).
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include "shapes/shapes.h"

using namespace streamrt;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

template <class Shape>
double hit(Vec3d o, Vec3d d, double param = 0.25, double t_min = 0.0, double t_max = kInf) {
    return Shape::template hit_t<double>(o, d, param, t_min, t_max);
}
template <class Shape>
Vec3d unit_normal(Vec3d p, double param = 0.25) {
    return normalize(Shape::template normal<double>(p, param));
}
void check_vec(Vec3d a, Vec3d b, double eps = 1e-12) {
    CHECK(a.x == doctest::Approx(b.x).epsilon(eps));
    CHECK(a.y == doctest::Approx(b.y).epsilon(eps));
    CHECK(a.z == doctest::Approx(b.z).epsilon(eps));
}
}  // namespace

TEST_CASE("sphere: outside, inside, miss, tangent, unnormalised direction") {
    CHECK(hit<SphereMath>({0, 0, 5}, {0, 0, -1}) == doctest::Approx(4.0));
    CHECK(hit<SphereMath>({0, 0, 0}, {0, 0, -1}) == doctest::Approx(1.0));   // from inside
    CHECK(hit<SphereMath>({0, 2, 5}, {0, 0, -1}) == kInf);                   // miss
    CHECK(hit<SphereMath>({0, 0, 5}, {0, 0, 1}) == kInf);                    // behind
    CHECK(hit<SphereMath>({0, 1, 5}, {0, 0, -1}) == doctest::Approx(5.0));   // tangent: touches at t=5
    CHECK(hit<SphereMath>({0, 0, 5}, {0, 0, -2}) == doctest::Approx(2.0));   // t scales with |d|
    CHECK(hit<SphereMath>({0, 0, 5}, {0, 0, -1}, 0, 0, 3.5) == kInf);        // beyond t_max
    // Off-axis: x = 0.6 enters at z = 0.8.
    CHECK(hit<SphereMath>({0.6, 0, 5}, {0, 0, -1}) == doctest::Approx(4.2));
    check_vec(unit_normal<SphereMath>({0.6, 0, 0.8}), {0.6, 0, 0.8});
}

TEST_CASE("sphere: far origin keeps precision (closest-approach discriminant)") {
    const double t = hit<SphereMath>({0, 0, 1e7}, {0, 0, -1});
    CHECK(t == doctest::Approx(1e7 - 1).epsilon(1e-15));
}

TEST_CASE("plane: hit, from below, parallel, lying in the plane") {
    CHECK(hit<PlaneMath>({0, 2, 0}, {0, -1, 0}) == doctest::Approx(2.0));
    CHECK(hit<PlaneMath>({0, -2, 0}, {0, 1, 0}) == doctest::Approx(2.0));
    CHECK(hit<PlaneMath>({0, 2, 0}, {1, 0, 0}) == kInf);
    CHECK(hit<PlaneMath>({0, 0, 0}, {1, 0, 0}) == kInf);
    CHECK(hit<PlaneMath>({0, 2, 0}, {0, 1, 0}) == kInf);
    CHECK(hit<PlaneMath>({1, 1, 0}, {0, -1, -1}) == doctest::Approx(1.0));
    check_vec(unit_normal<PlaneMath>({3, 0, 4}), {0, 1, 0});
}

TEST_CASE("cube: faces, inside, edge, parallel to a face, miss") {
    CHECK(hit<CubeMath>({0, 0, 5}, {0, 0, -1}) == doctest::Approx(4.0));
    CHECK(hit<CubeMath>({0, 0, 0}, {1, 0, 0}) == doctest::Approx(1.0));      // from inside
    CHECK(hit<CubeMath>({0, 2, 5}, {0, 0, -1}) == kInf);
    CHECK(hit<CubeMath>({0.5, 0.5, 5}, {0, 0, -1}) == doctest::Approx(4.0));
    // Diagonal through the corner region: from (3,3,0) towards the origin enters at (1,1,0).
    CHECK(hit<CubeMath>({3, 3, 0}, {-1, -1, 0}) == doctest::Approx(2.0));
    // Parallel to the y faces, inside the slab.
    CHECK(hit<CubeMath>({5, 0.25, 0}, {-1, 0, 0}) == doctest::Approx(4.0));
    check_vec(unit_normal<CubeMath>({1, 0.3, -0.2}), {1, 0, 0});
    check_vec(unit_normal<CubeMath>({0.1, -1, 0.9}), {0, -1, 0});
    check_vec(unit_normal<CubeMath>({0.1, 0.2, -1}), {0, 0, -1});
}

TEST_CASE("cylinder: side, caps, along the axis, from inside, miss") {
    CHECK(hit<CylinderMath>({0, 0, 5}, {0, 0, -1}) == doctest::Approx(4.0));
    CHECK(hit<CylinderMath>({0, 5, 0}, {0, -1, 0}) == doctest::Approx(4.0));   // top cap, along the axis
    CHECK(hit<CylinderMath>({0.5, -5, 0}, {0, 1, 0}) == doctest::Approx(4.0)); // bottom cap
    CHECK(hit<CylinderMath>({0, 0, 0}, {1, 0, 0}) == doctest::Approx(1.0));    // inside, side
    CHECK(hit<CylinderMath>({0, 0, 0}, {0, 1, 0}) == doctest::Approx(1.0));    // inside, cap
    CHECK(hit<CylinderMath>({0, 2, 5}, {0, 0, -1}) == kInf);                  // above
    CHECK(hit<CylinderMath>({2, 5, 0}, {0, -1, 0}) == kInf);                  // parallel, outside
    check_vec(unit_normal<CylinderMath>({0.6, 0.2, 0.8}), {0.6, 0, 0.8});
    check_vec(unit_normal<CylinderMath>({0.3, 1, 0.1}), {0, 1, 0});
    check_vec(unit_normal<CylinderMath>({0.3, -1, 0.1}), {0, -1, 0});
}

TEST_CASE("cone: side, base cap, apex, along the axis, parallel to a generator") {
    // Along -z at y = 0 the radius is 0.5.
    CHECK(hit<ConeMath>({0, 0, 5}, {0, 0, -1}) == doctest::Approx(4.5));
    CHECK(hit<ConeMath>({0, 5, 0}, {0, -1, 0}) == doctest::Approx(4.0));    // apex
    CHECK(hit<ConeMath>({0, -5, 0}, {0, 1, 0}) == doctest::Approx(4.0));    // base cap
    CHECK(hit<ConeMath>({0, 0, 0}, {0, -1, 0}) == doctest::Approx(1.0));    // inside, down to the cap
    CHECK(hit<ConeMath>({0, 1.5, 5}, {0, 0, -1}) == kInf);                  // above the apex
    // A ray parallel to the generator (slope 1/2): direction (0,-2,1)/.. from above the side.
    // Line x=0: z = 0.5 (1 - y) is the generator; shifted outwards: z = 0.5(1-y) + 0.5.
    // Ray from (0, 3, -0.5) with d = (0, -2, 1) stays parallel and hits the base cap at y=-1:
    // t = 2, point (0, -1, 1.5): outside radius 1, so it misses.
    CHECK(hit<ConeMath>({0, 3, -0.5}, {0, -2, 1}) == kInf);
    // Parallel to the generator but inside the cone's extension: (0,3,-1.5) d=(0,-2,1): the
    // linear root lies where z = 0.5 (1 - y): -1.5 + t = -0.5 (1 - 3 + 2t)... mirrored side
    // z = -0.5 (1 - y): -1.5 + t = -0.5 (-2 + 2 t) -> t = 1.25, y = 0.5, z = -0.25.
    CHECK(hit<ConeMath>({0, 3, -1.5}, {0, -2, 1}) == doctest::Approx(1.25));
    check_vec(unit_normal<ConeMath>({0.5, 0, 0}), normalize(Vec3d{0.5, 0.25, 0}));
    check_vec(unit_normal<ConeMath>({0.2, -1, 0.1}), {0, -1, 0});
    check_vec(unit_normal<ConeMath>({0, 1, 0}), {0, 1, 0});
}

TEST_CASE("every shape: NaN and zero directions miss, never NaN") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CanonicalShapes::for_each([&](auto s) {  // every registered shape (shapes/shapes.h)
        using S = decltype(s);
        const std::string name(S::name);
        CAPTURE(name);
        CHECK(hit<S>({0, 0, 5}, {nan, 0, -1}) == kInf);
        CHECK(hit<S>({nan, 0, 5}, {0, 0, -1}) == kInf);
        CHECK(hit<S>({0, 0, 5}, {0, 0, 0}) == kInf);
    });
}
