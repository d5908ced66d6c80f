// Fresnel (material fresnel=true): Schlick's reflectance against the exact Fresnel equations
// (the unpolarised average of rs^2 and rp^2, computed here from Snell's law), and pixels
// whose weights are worked out by hand, rendered by both engines.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "render/shading.h"
#include "scene/parser.h"
#include "stream/stream_renderer.h"
#include "kernels/kernel_table.h"
#include "one_pixel.h"

using namespace streamrt;

namespace {
/// Exact unpolarised reflectance from index n1 into n2 at incidence cos_i (1 beyond the
/// critical angle).
double exact_fresnel(double n1, double n2, double cos_i) {
    const double sin_t = n1 / n2 * std::sqrt(std::max(0.0, 1 - cos_i * cos_i));
    if (sin_t >= 1) return 1;
    const double cos_t = std::sqrt(1 - sin_t * sin_t);
    const double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    const double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    return (rs * rs + rp * rp) / 2;
}

/// Schlick through the engine's functions for a ray at angle theta to the normal (+y, the
/// outward normal of a surface whose inside has index ior), from outside or inside.
double schlick_at(double ior, double theta, bool from_inside) {
    const Vec3d n{0, 1, 0};
    const Vec3d d = from_inside ? Vec3d{std::sin(theta), std::cos(theta), 0} : Vec3d{std::sin(theta), -std::cos(theta), 0};
    const double r = (ior - 1) / (ior + 1);
    return schlick_reflectance(r * r, refraction(d, n, ior));
}
}  // namespace

TEST_CASE("fresnel: Schlick against the exact equations, entering and leaving") {
    // Bounds on |Schlick - exact| over all angles, from a fine sweep of both formulas (the
    // approximation is worst near grazing): 0.036 at n = 1.5, 0.060 at n = 1.33.
    for (const auto& [ior, bound] : {std::pair{1.5, 0.037}, std::pair{1.33, 0.061}, std::pair{1.7, 0.033}}) {
        CAPTURE(ior);
        double worst = 0;
        for (int i = 0; i <= 890; ++i) {
            const double theta = i * M_PI / 1800;  // 0 .. 89 degrees
            const double cos_i = std::cos(theta);
            worst = std::max(worst, std::fabs(schlick_at(ior, theta, false) - exact_fresnel(1, ior, cos_i)));
            // Leaving the denser medium below the critical angle: Schlick must take the
            // transmitted (outside) angle; the exact reflectance is the same both ways.
            const double sin_t = ior * std::sin(theta);
            if (sin_t < 1) {
                const double inside = schlick_at(ior, theta, true);
                worst = std::max(worst, std::fabs(inside - exact_fresnel(ior, 1, cos_i)));
                CHECK(inside == doctest::Approx(schlick_at(ior, std::asin(sin_t), false)).epsilon(1e-9));
            } else {
                CHECK(schlick_at(ior, theta, true) == 1.0);  // total internal reflection
            }
        }
        CHECK(worst < bound);
    }
    // Normal incidence: both are ((n - 1) / (n + 1))^2 = 0.04 at n = 1.5.
    CHECK(exact_fresnel(1, 1.5, 1) == doctest::Approx(0.04).epsilon(1e-12));
    CHECK(schlick_at(1.5, 0, false) == doctest::Approx(0.04).epsilon(1e-12));
    CHECK(schlick_at(1.5, 0, true) == doctest::Approx(0.04).epsilon(1e-12));
    // Grazing: everything is reflected.
    CHECK(exact_fresnel(1, 1.5, 0) == doctest::Approx(1.0));
    CHECK(schlick_at(1.5, M_PI / 2, false) == doctest::Approx(1.0).epsilon(1e-12));
    // 60 degrees: 0.04 + 0.96 (1 - 1/2)^5 = 0.07 (exact: 0.0892).
    CHECK(schlick_at(1.5, M_PI / 3, false) == doctest::Approx(0.07).epsilon(1e-12));
    // Just past the critical angle asin(1/1.5) = 41.81 degrees, from inside: 1.
    CHECK(schlick_at(1.5, std::asin(1 / 1.5) + 1e-6, true) == 1.0);
}

namespace {
// A glass plane (black, so it adds no local colour) above a red plane lit only by the
// ambient term (ambient 1, ambi 1); a blue background behind the reflected ray. The pixel is
// then trans' * red + refl' * blue with refl' = refl + trans R, trans' = trans (1 - R).
std::string glass_scene(const std::string& camera, const std::string& glass) {
    return "image width=1 height=1 spp=1 degree=4 depth=1\nambient 1\nbackground 0,0,1\n" + camera +
           "\nplane color=0,0,0 ambi=0 diff=0 spec=0 ior=1.5 " + glass +
           "\nplane color=1,0,0 ambi=1 diff=0 translate=0,-1,0\n";
}
}  // namespace

TEST_CASE("fresnel: hand-computed pixels, head-on and at 60 degrees, both engines") {
    // Looking straight down at the glass (y = 0) from (0,1,0): R = R0 = 0.04.
    const std::string down = "camera eye=0,1,0 look=0,0,0 up=0,0,-1";
    // refl 0.5, trans 0.5: refl' = 0.5 + 0.5 * 0.04 = 0.52, trans' = 0.48.
    test::check_one_pixel(parse_scene(glass_scene(down, "refl=0.5 trans=0.5 fresnel=true"), "f.cfg"), 0.48, 0, 0.52);
    // The handout's fixed weights without fresnel (and with fresnel=false).
    test::check_one_pixel(parse_scene(glass_scene(down, "refl=0.5 trans=0.5"), "f.cfg"), 0.5, 0, 0.5);
    test::check_one_pixel(parse_scene(glass_scene(down, "refl=0.5 trans=0.5 fresnel=false"), "f.cfg"), 0.5, 0, 0.5);
    // At 60 degrees to the normal (view direction (sqrt 3, -1, 0) / 2): R = 0.07; with
    // refl = 0 the reflected child exists only because of Fresnel.
    const std::string oblique = "camera eye=0,1,0 look=1.7320508075688772,0,0";
    test::check_one_pixel(parse_scene(glass_scene(oblique, "trans=1 fresnel=true"), "f.cfg"), 0.93, 0, 0.07);
    test::check_one_pixel(parse_scene(glass_scene(oblique, "trans=0.8 refl=0.1 fresnel=true"), "f.cfg"),
                          0.8 * 0.93, 0, 0.1 + 0.8 * 0.07);
}

TEST_CASE("fresnel: a glass with refl = 0 builds spawn(reflect) only with fresnel=true") {
    const auto stages = [](const std::string& glass) {
        const Scene s = parse_scene("image width=8 height=8 degree=5 depth=2\ncamera eye=0,0,5 look=0,0,0\n"
                                    "light point pos=0,5,5\nsphere trans=0.9 " + glass + "\n",
                                    "p.cfg");
        std::string all;
        for (const std::string& st : StreamRenderer(s, best_isa()).built_stages()) all += st + " ";
        return all;
    };
    CHECK(stages("ior=1.5 fresnel=true").find("spawn(reflect) spawn(refract)") != std::string::npos);
    CHECK(stages("ior=1.5").find("spawn(reflect)") == std::string::npos);
    CHECK(stages("ior=1.5 fresnel=false").find("spawn(reflect)") == std::string::npos);
    CHECK(stages("ior=1 fresnel=true").find("spawn(reflect)") == std::string::npos);  // no interface
}
