// Area lights, falloff and soft spot edges against closed forms, through both engines. One
// pixel: the camera at (0,-3,4) looks at (0,0,1) on the unit sphere (normal +z); the material
// has no ambient or highlight, so the pixel is the light's average of (N.w) x visibility x
// scale over the light's samples (docs/scene-format.md, "Area lights and soft shadows").
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "driver/render.h"
#include "render/shading.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

constexpr double kPi = std::numbers::pi;

const std::string kHead =
    "image width=1 height=1 spp=1 depth=0 degree=5\n"
    "camera eye=0,-3,4 look=0,0,1 up=0,0,1 fov=5\n"
    "ambient 0\n"
    "sphere color=1,1,1 ambi=0 diff=1 spec=0\n";

/// Renders `body` with both engines and checks the one pixel's red channel is within `tol`.
void check_pixel_near(const std::string& body, double expected, double tol) {
    const Scene scene = parse_scene(kHead + body, "area.cfg");
    for (EngineKind e : {EngineKind::Recursive, EngineKind::Stream}) {
        CAPTURE(engine_name(e));
        Parallelism par(1);
        const RenderResult res = render_scene(scene, e, par);
        const double got = res.image.pixel(0, 0)[0];
        CAPTURE(got);
        CAPTURE(expected);
        CHECK(std::abs(got - expected) <= tol);
    }
}

// The sphere light: centre (0,0,4), radius 1.5, seen from p = (0,0,1) at distance D = 3 along
// the normal; the cap's half-angle alpha has sin alpha = R / D.
constexpr int kSamples = 4096;  // a 64 x 64 lattice
const double kCosAlpha = std::sqrt(1.0 - 1.5 * 1.5 / 9.0);

/// Mean of N.w over the cap's directions (uniform in solid angle) on the side w.y < k w.z:
/// (1 / Omega) integral over theta in [0, alpha] of cos theta sin theta m(theta), where
/// m(theta) is the measure of the azimuths phi with sin theta sin phi < k cos theta, and
/// Omega = 2 pi (1 - cos alpha). Simpson's rule on 20000 intervals (m is continuous).
double visible_mean(double k) {
    const double alpha = std::acos(kCosAlpha);
    const auto f = [&](double th) {
        if (th <= 0) return 0.0;
        const double c = k / std::tan(th);
        const double m = c >= 1 ? 2 * kPi : c <= -1 ? 0.0 : kPi + 2 * std::asin(c);
        return std::cos(th) * std::sin(th) * m;
    };
    const int n = 20000;
    const double h = alpha / n;
    double sum = f(0) + f(alpha);
    for (int i = 1; i < n; ++i) sum += f(i * h) * (i % 2 ? 4 : 2);
    return sum * h / 3 / (2 * kPi * (1 - kCosAlpha));
}

const std::string kSphereLight = "light sphere pos=0,0,4 radius=1.5 samples=4096\n";

/// A thin opaque slab z in [1.99, 2.01] over y >= y0, between p and the light (whose
/// nearest points are at z = 2.5). From p it hides the directions with w.y >= k w.z,
/// k = y0 / (2.01 - 1): the cap cut by a plane through p.
std::string blocker(double y0) {
    return "cube color=1,1,1 scale=50,25,0.01 translate=0," + std::to_string(y0 + 25) + ",2\n";
}

}  // namespace

TEST_CASE("sphere light, unoccluded: the mean of N.w over the visible cap, (1 + cos alpha) / 2") {
    // The integrand N.w = cos theta lies in [cos alpha, 1]: a sample mean of N values has a
    // standard deviation below (1 - cos alpha) / 2 / sqrt(N) (stratification only lowers it);
    // 4 of them. Proven against sampling theta uniformly instead of cos theta (the mean is
    // then sin alpha / alpha = 0.955 instead of 0.933: off by 10x the tolerance).
    const double expected = (1 + kCosAlpha) / 2;
    const double tol = 4 * (1 - kCosAlpha) / 2 / std::sqrt(double(kSamples));
    check_pixel_near(kSphereLight, expected, tol);
    // Tilted by 40 degrees (the cap stays above the horizon): by symmetry the mean direction
    // is the axis times (1 + cos alpha) / 2, so the mean of N.w is cos 40 (1 + cos alpha) / 2.
    const double b = 40 * kPi / 180;
    const std::string tilted = "light sphere pos=0," + std::to_string(3 * std::sin(b)) + "," +
                               std::to_string(1 + 3 * std::cos(b)) + " radius=1.5 samples=4096\n";
    check_pixel_near(tilted, std::cos(b) * expected, tol);
}

TEST_CASE("sphere light, penumbra: a cap cut by a plane through the shaded point") {
    // Only the lattice cells the visibility boundary crosses can err, each by at most its
    // 1/N share, with independent jitter. The boundary (sin phi = k cot theta in the lattice's
    // (theta, phi) coordinates) crosses each of the 64 columns and rows at most twice: C <= 256
    // cells, a standard deviation below sqrt(C) / N; 4 of them (0.016). Proven against
    // sampling theta uniformly instead of cos theta (off by 0.08 at y0 = 0 and 0.04 at
    // y0 = 0.3).
    const double tol = 4 * std::sqrt(256.0) / kSamples;
    // The slab's edge straight over p: exactly half the cap, by symmetry.
    CHECK(visible_mean(0.0) == doctest::Approx((1 + kCosAlpha) / 4).epsilon(1e-9));
    check_pixel_near(kSphereLight + blocker(0.0), (1 + kCosAlpha) / 4, tol);
    check_pixel_near(kSphereLight + blocker(0.3), visible_mean(0.3 / 1.01), tol);
    check_pixel_near(kSphereLight + blocker(-0.4), visible_mean(-0.4 / 1.01), tol);
}

TEST_CASE("rect light with inverse-square falloff: Lambert's polygon formula") {
    // The pixel is (1/A) integral over the rect of cos theta cos theta' / r^2 dA, and
    // Lambert: integral = 1/2 sum over edges of Theta_i (N . n_i), Theta_i the angle the edge
    // subtends at p, n_i the unit normal of the plane through p and the edge.
    // Rect: corner (-0.5, 0.2, 3), u = (0,1,0), v = (1.5,0,0): u x v = -z, facing p.
    const glm::dvec3 p{0, 0, 1}, corner{-0.5, 0.2, 3}, u{0, 1, 0}, v{1.5, 0, 0};
    const glm::dvec3 q[4] = {corner - p, corner + u - p, corner + u + v - p, corner + v - p};
    double sum = 0;
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 a = glm::normalize(q[i]), b = glm::normalize(q[(i + 1) % 4]);
        sum += std::acos(glm::dot(a, b)) * glm::normalize(glm::cross(a, b)).z;
    }
    const double expected = std::abs(sum) / 2 / 1.5;
    // The integrand lies in [0, 1/4] (r >= 2): 4 standard deviations of the plain mean.
    const double tol = 4 * 0.125 / std::sqrt(double(kSamples));
    // Proven against dropping the emitter cosine (off by 0.015, twice the tolerance).
    check_pixel_near("light rect pos=-0.5,0.2,3 u=0,1,0 v=1.5,0,0 samples=4096 falloff=inverse_square\n", expected,
                     tol);
    // One-sided: the same rect turned over (u and v swapped) does not light p.
    check_pixel_near("light rect pos=-0.5,0.2,3 u=1.5,0,0 v=0,1,0 samples=16\n", 0.0, 1e-6);
}

TEST_CASE("falloff and soft spot edges: closed forms") {
    // A point light 3 units above p along the normal: 1 / 9 with inverse-square falloff.
    check_pixel_near("light point pos=0,0,4 falloff=inverse_square\n", 1.0 / 9.0, 1e-6);
    // A spot 15 degrees off its axis, angle 20, soft 10: smoothstep of the cosine from
    // cos 20 (0) to cos 10 (1). Proven against a hard edge (1).
    const double d = kPi / 180;
    const double x = (std::cos(15 * d) - std::cos(20 * d)) / (std::cos(10 * d) - std::cos(20 * d));
    const std::string axis = std::to_string(std::sin(15 * d)) + ",-" + std::to_string(std::cos(15 * d));
    check_pixel_near("light spot pos=0,0,4 dir=0," + axis + " angle=20 soft=10\n", x * x * (3 - 2 * x), 1e-5);
    // Inside angle - soft: full light; outside the cone: none.
    check_pixel_near("light spot pos=0,0,4 dir=0,0,-1 angle=20 soft=10\n", 1.0, 1e-6);
    check_pixel_near("light spot pos=0,0,4 dir=0,0.5,-1 angle=20 soft=10\n", 0.0, 1e-6);
}

TEST_CASE("the sphere light's azimuth: cos and sin of a turn against std::cos and std::sin") {
    // Reduction to the nearest quarter turn and the Taylor polynomials on [-pi/4, pi/4]: the
    // first terms left out are (pi/4)^11 / 11! < 1.8e-9 (sin) and (pi/4)^12 / 12! < 1.2e-10
    // (cos), plus rounding in double. Proven against a wrong quadrant rotation (q = 1 as
    // q = 3: off by 2 at u = 0.3).
    for (int i = 0; i < 4000; ++i) {
        const double u = i / 4000.0;
        double c = 0, s = 0;
        simd::cos_sin_of_turn(u, c, s);
        CAPTURE(u);
        CHECK(std::abs(c - std::cos(2 * kPi * u)) <= 1e-8);
        CHECK(std::abs(s - std::sin(2 * kPi * u)) <= 1e-8);
    }
}

TEST_CASE("disk light facing p: the mean of cos^2 over the disk, and 1 / (h^2 + R^2) with falloff") {
    // Centre (0,0,3), h = 2 above p = (0,0,1) along the normal, radius R = 1.5, lit side -z.
    // A point at radius r on the disk is seen under cos theta = h / sqrt(h^2 + r^2), both at p
    // (N.w) and at the emitter, so the pixel is the disk's mean of cos^2 theta:
    // (1 / (pi R^2)) integral 0..R of h^2 / (h^2 + r^2) 2 pi r dr = (h^2 / R^2) ln(1 + R^2 / h^2);
    // with falloff=inverse_square the integrand gains 1 / (h^2 + r^2) and the mean is
    // (1 / R^2)(1 - h^2 / (h^2 + R^2)) = 1 / (h^2 + R^2).
    const double h = 2, R = 1.5;
    const double plain = h * h / (R * R) * std::log(1 + R * R / (h * h));
    const double falloff = 1 / (h * h + R * R);
    // Integrands in [h^2 / (h^2 + R^2), 1] and [h^2 / (h^2 + R^2)^2, 1 / h^2]: 4 standard
    // deviations of the plain mean of 4096 samples. Proven against sampling the radius
    // uniformly instead of as R sqrt(u1) (0.858 instead of 0.793: 6x the tolerance; 0.187
    // instead of 0.160 with falloff); dropping the emitter cosine would give
    // (2h / R^2)(sqrt(h^2 + R^2) - h) = 0.889.
    const double tol_plain = 4 * (1 - h * h / (h * h + R * R)) / 2 / std::sqrt(double(kSamples));
    const double tol_falloff = 4 * (1 / (h * h) - h * h / std::pow(h * h + R * R, 2)) / 2 / std::sqrt(double(kSamples));
    check_pixel_near("light disk pos=0,0,3 dir=0,0,-1 radius=1.5 samples=4096\n", plain, tol_plain);
    check_pixel_near("light disk pos=0,0,3 dir=0,0,-1 radius=1.5 samples=4096 falloff=inverse_square\n", falloff,
                     tol_falloff);
    // One-sided: facing away, p gets nothing.
    check_pixel_near("light disk pos=0,0,3 dir=0,0,1 radius=1.5 samples=16\n", 0.0, 1e-6);
}
