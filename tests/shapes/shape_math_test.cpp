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

TEST_CASE("sphere: the packet pre-test never rejects a ray that hits (grazing rays in float)") {
    // Known answers: the line at distance h from the centre meets the unit sphere iff h <= 1.
    CHECK(SphereMath::may_hit<float>({0.f, 2.f, 5.f}, {0.f, 0.f, -1.f}) == false);   // h = 2
    CHECK(SphereMath::may_hit<float>({0.f, 1.1f, 5.f}, {0.f, 0.f, -1.f}) == false);  // h = 1.1
    CHECK(SphereMath::may_hit<float>({0.f, 0.5f, 5.f}, {0.f, 0.f, -1.f}) == true);   // h = 0.5
    CHECK(SphereMath::may_hit<float>({0.f, 0.5f, 5.f}, {0.f, 0.f, 1.f}) == true);    // the line, not the ray
    // Far away the margin widens, in proportion to the distance (2^-17 (a |w| |o| + |w|^2 +
    // a^2), by hand): at 1000 radii a line 1.01 radii from the centre is rejected (a^2 - |w|^2
    // = -0.0201 a^2 against a margin of 0.0077 a^2), one 1.001 radii away is let through
    // (-0.002 a^2); at 10 radii, 1.0002 radii away is rejected (-0.0004 a^2 against 0.0001 a^2).
    CHECK(SphereMath::may_hit<float>({1.01f, 0.f, 1000.f}, {0.f, 0.f, -2.f}) == false);
    CHECK(SphereMath::may_hit<float>({1.001f, 0.f, 1000.f}, {0.f, 0.f, -2.f}) == true);
    CHECK(SphereMath::may_hit<float>({0.f, 1.0002f, 10.f}, {0.f, 0.f, -1.f}) == false);
    // Rays from up to 1e4 away (unnormalised directions) aimed inside and outside the rim by
    // 1e-7 to 1e-2, where b^2 - a c cancels: wherever the float solve finds a hit, the
    // pre-test lets it through.
    int hits = 0, rejected_hits = 0, misses_rejected = 0;
    for (int k = 0; k < 4000; ++k) {
        const double dist = std::pow(10.0, 0.5 + 3.5 * (k % 40) / 39.0);          // 3 .. 1e4 away
        const int m = k / 40;  // 0 .. 99: inside and outside the rim by 1e-7 .. 1e-2
        const double h = 1.0 + (m % 2 ? 1.0 : -1.0) * std::pow(10.0, -7.0 + 5.0 * (m / 2) / 49.0);
        const double ang = 0.37 * k;
        const Vec3f o{float(h * std::cos(ang)), float(h * std::sin(ang)), float(dist)};
        const Vec3f d{0.f, 0.f, float(-(1.0 + (k % 7)))};  // |d| from 1 to 7
        const float t = SphereMath::hit_t<float>(o, d, 0.f, 0.f, std::numeric_limits<float>::infinity());
        const bool may = SphereMath::may_hit<float>(o, d);
        if (t < std::numeric_limits<float>::infinity()) {
            ++hits;
            if (!may) ++rejected_hits;
        } else if (!may) {
            ++misses_rejected;
        }
    }
    CHECK(hits > 1000);                 // the sweep does reach the rim from both sides
    CHECK(rejected_hits == 0);          // never a hit thrown away
    CHECK(misses_rejected > 100);       // and the pre-test does reject the clearer misses
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
