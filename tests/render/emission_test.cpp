// Emission (material emission=R,G,B): one-pixel scenes whose colour is worked out by hand,
// through both engines. The camera at (0,0,5) looks at a unit sphere; the centre ray hits
// (0,0,1) with normal (0,0,1).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "driver/render.h"
#include "render/one_pixel.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

const std::string kHead =
    "image width=1 height=1 spp=1 depth=3\n"
    "camera eye=0,0,5 look=0,0,0 up=0,1,0 fov=10\n"
    "background 0.2,0.3,0.4\n";

Scene pixel_scene(const std::string& body, int degree, double ambient = 0.1) {
    return parse_scene(kHead + "ambient " + std::to_string(ambient) + "\nimage degree=" + std::to_string(degree) +
                           "\n" + body,
                       "emission.cfg");
}

/// The pixel of both engines, each channel exactly the float of the value given.
void check_exact_pixel(const Scene& scene, double r, double g, double b) {
    for (EngineKind e : {EngineKind::Recursive, EngineKind::Stream}) {
        const std::string engine(engine_name(e));
        CAPTURE(engine);
        Parallelism par(1);
        const RenderResult res = render_scene(scene, e, par);
        const float* p = res.image.pixel(0, 0);
        CHECK(p[0] == float(r));
        CHECK(p[1] == float(g));
        CHECK(p[2] == float(b));
    }
}

}  // namespace

TEST_CASE("emission: a surface without ambient and diffuse terms shows exactly its emission, both engines") {
    // ambi = diff = 0 (and no highlight): the lit terms are exact zeros, the pixel is the
    // emission to the last bit, whatever the light and the object's colour.
    const std::string emitter = "sphere color=0.9,0.1,0.5 ambi=0 diff=0 emission=0.2,0.4,0.6\n";
    for (int degree = 2; degree <= 5; ++degree) {
        CAPTURE(degree);
        check_exact_pixel(pixel_scene(emitter + "light point pos=0,4,5\n", degree), 0.2, 0.4, 0.6);
    }
    // Degree 1 ignores ambi and diff (alpha Col plus Lambert with white light): with no
    // ambient and no light the emission alone remains.
    check_exact_pixel(pixel_scene(emitter, 1, 0.0), 0.2, 0.4, 0.6);
    // Degree 0: the flat colour, without emission.
    check_exact_pixel(pixel_scene(emitter + "light point pos=0,4,5\n", 0), 0.9, 0.1, 0.5);
    // The checker replaces the colour, not the emission.
    check_exact_pixel(pixel_scene("sphere ambi=0 diff=0 checker=1,0,0 cell=0.3 emission=0.2,0.4,0.6\n", 2), 0.2, 0.4,
                      0.6);
}

TEST_CASE("emission: added to the Lambert and ambient terms, worked out by hand, both engines") {
    // The light at (0,4,5) seen from (0,0,1): w = (0,1,1)/sqrt(2), N.w = 1/sqrt(2).
    const std::string body =
        "sphere color=0.8,0.4,0.2 ambi=0.5 diff=0.6 emission=0.05,0.1,0.3\nlight point pos=0,4,5 color=0.5,0.5,0.5\n";
    const double nw = 1 / std::sqrt(2.0);
    const double e[3] = {0.05, 0.1, 0.3}, col[3] = {0.8, 0.4, 0.2};
    // Degree 1: (alpha + N.w) Col + emission (the light taken as white, ambi and diff unused).
    const double k1 = 0.1 + nw;
    test::check_one_pixel(pixel_scene(body, 1), k1 * col[0] + e[0], k1 * col[1] + e[1], k1 * col[2] + e[2]);
    // Degrees 2 and 5 (nothing blocks the light): (alpha ambi + light diff N.w) Col + emission.
    const double k2 = 0.1 * 0.5 + 0.5 * 0.6 * nw;
    for (int degree : {2, 5}) {
        CAPTURE(degree);
        test::check_one_pixel(pixel_scene(body, degree), k2 * col[0] + e[0], k2 * col[1] + e[1], k2 * col[2] + e[2]);
    }
}

TEST_CASE("emission: not a light source, and seen in a mirror, both engines") {
    // A bright emitter beside the white sphere lights nothing: with no light the sphere keeps
    // its ambient term alone, alpha ambi Col = 0.1.
    test::check_one_pixel(pixel_scene("sphere color=1,1,1\nsphere color=0,0,0 ambi=0 diff=0 emission=50,50,50 "
                                      "translate=2.2,0,0\n",
                                      5),
                          0.1, 0.1, 0.1);
    // A mirror (refl 0.5) sends the centre ray back along +z to an emitter behind the camera,
    // black but for its emission: 0.5 x (0, 0.6, 0.2).
    test::check_one_pixel(pixel_scene("sphere color=1,1,1 ambi=0 diff=0 refl=0.5\n"
                                      "sphere color=0,0,0 ambi=0 diff=0 emission=0,0.6,0.2 translate=0,0,20\n",
                                      3),
                          0.0, 0.3, 0.1);
}
