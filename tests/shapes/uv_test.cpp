// Each canonical shape's texture mapping (shapes/*_math.h uv): analytic surface points and
// their (u, v) worked out by hand from the formulas of docs/scene-format.md, "Textures and
// UV mapping".
#include <doctest/doctest.h>

#include "shapes/shapes.h"

using namespace streamrt;

namespace {

template <class S>
void check_uv(double x, double y, double z, double u, double v, double param = 0.0) {
    CAPTURE(S::name);
    CAPTURE(x);
    CAPTURE(y);
    CAPTURE(z);
    const UvT<double> d = S::template uv<double>(Vec3d{x, y, z}, param);
    CHECK(d.u == doctest::Approx(u).epsilon(1e-12));
    CHECK(d.v == doctest::Approx(v).epsilon(1e-12));
    const UvT<float> f = S::template uv<float>(Vec3T<float>{float(x), float(y), float(z)}, float(param));
    CHECK(f.u == doctest::Approx(u).epsilon(1e-6));
    CHECK(f.v == doctest::Approx(v).epsilon(1e-6));
}

}  // namespace

// Proven against: the sphere's u from atan2(z, x) (the +z point went to u = 0.75).
TEST_CASE("uv: sphere, longitude and latitude") {
    check_uv<SphereMath>(0, 0, 1, 0.5, 0.5);   // atan2(0, 1) = 0, asin(0) = 0
    check_uv<SphereMath>(1, 0, 0, 0.75, 0.5);  // atan2(1, 0) = pi/2: 0.5 + 1/4
    check_uv<SphereMath>(-1, 0, 0, 0.25, 0.5);
    check_uv<SphereMath>(0, 1, 0, 0.5, 1.0);   // asin(1) = pi/2: 0.5 + 1/2
    check_uv<SphereMath>(0, -1, 0, 0.5, 0.0);
    // (0, 1/2, sqrt(3)/2): asin(1/2) = pi/6, v = 0.5 + 1/6.
    check_uv<SphereMath>(0, 0.5, 0.8660254037844386, 0.5, 0.5 + 1.0 / 6.0);
}

TEST_CASE("uv: cube, one image per face") {
    check_uv<CubeMath>(1, 0.5, -0.5, 0.25, 0.75);    // x face: ((z + 1) / 2, (y + 1) / 2)
    check_uv<CubeMath>(0.2, -1, 0.6, 0.6, 0.8);      // y face: ((x + 1) / 2, (z + 1) / 2)
    check_uv<CubeMath>(0.5, -0.5, 1, 0.75, 0.25);    // z face: ((x + 1) / 2, (y + 1) / 2)
    check_uv<CubeMath>(-0.5, 0.5, -1, 0.25, 0.75);
}

TEST_CASE("uv: cylinder and cone, angle and height, caps planar") {
    check_uv<CylinderMath>(0, 0.5, 1, 0.5, 0.75);      // side: (0.5 + 0, (0.5 + 1) / 2)
    check_uv<CylinderMath>(1, -1 + 0.5, 0, 0.75, 0.25);
    check_uv<CylinderMath>(0.5, 1, -0.5, 0.75, 0.25);  // top cap: ((x + 1) / 2, (z + 1) / 2)
    check_uv<CylinderMath>(-0.5, -1, 0, 0.25, 0.5);    // bottom cap
    check_uv<ConeMath>(0.5, 0, 0, 0.75, 0.5);          // side at y = 0 (radius 1/2)
    check_uv<ConeMath>(0, -0.5, -0.75, 1.0, 0.25);     // side on -z: the seam, atan2(+0, -) = pi
    check_uv<ConeMath>(0, -1, 0.5, 0.5, 0.75);         // base
}

TEST_CASE("uv: torus, the two angles") {
    // Minor radius 1/4. Outer equator on +x: ring angle pi/2 (u = 0.75), tube angle
    // atan2(0, 1/4) = 0 (v = 0.5).
    check_uv<TorusMath>(1.25, 0, 0, 0.75, 0.5, 0.25);
    // Top of the tube over +z: u = 0.5, tube angle atan2(1/4, 0) = pi/2: v = 0.75.
    check_uv<TorusMath>(0, 0.25, 1, 0.5, 0.75, 0.25);
    // Bottom of the tube: -pi/2, v = 0.25.
    check_uv<TorusMath>(0, -0.25, 1, 0.5, 0.25, 0.25);
}

TEST_CASE("uv: plane and disk, planar") {
    check_uv<PlaneMath>(3, 0, -2, 3, -2);            // (x, z), repeated by the lookup
    check_uv<DiskMath>(0.5, 0, -1, 0.75, 0.0);       // ((x + 1) / 2, (z + 1) / 2)
    check_uv<DiskMath>(0, 0, 0, 0.5, 0.5);
}

TEST_CASE("uv: densities, the rate of (u, v) per canonical unit") {
    CHECK(SphereMath::uv_density(0.0) == doctest::Approx(1.0 / 3.141592653589793));  // dv/ds = 1/pi
    CHECK(PlaneMath::uv_density(0.0) == 1.0);
    CHECK(CubeMath::uv_density(0.0) == 0.5);
    CHECK(TorusMath::uv_density(0.25) == doctest::Approx(1.0 / (2 * 3.141592653589793 * 0.25)));
    CHECK(TorusMath::uv_density(2.0) == doctest::Approx(1.0 / (2 * 3.141592653589793)));
}
