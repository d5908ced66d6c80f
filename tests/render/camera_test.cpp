// Primary rays through the centre and the corners, for both camera forms.
#include <doctest/doctest.h>

#include <cmath>

#include "render/camera_rays.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {
void check_dir(const Vec3d& got, Vec3d want) {
    want = normalize(want);
    CHECK(got.x == doctest::Approx(want.x).epsilon(1e-12));
    CHECK(got.y == doctest::Approx(want.y).epsilon(1e-12));
    CHECK(got.z == doctest::Approx(want.z).epsilon(1e-12));
}
}  // namespace

TEST_CASE("look-at camera: eye, centre and corner rays") {
    const Scene s = parse_scene("image width=200 height=100\ncamera eye=0,0,5 look=0,0,0 up=0,1,0 fov=90\n"
                                "sphere\nlight point pos=0,5,5\n", "cam.cfg");
    const auto cam = CameraRays<double>::from(s);
    CHECK(cam.origin.x == doctest::Approx(0.0));
    CHECK(cam.origin.z == doctest::Approx(5.0));
    check_dir(cam.direction(100, 50), {0, 0, -1});
    // fov 90: half-height tan(45) = 1 at unit distance; aspect 2 makes half-width 2.
    check_dir(cam.direction(0, 0), {-2, 1, -1});
    check_dir(cam.direction(200, 100), {2, -1, -1});
}

TEST_CASE("look-at camera looking down +x with a tilted up vector stays orthonormal") {
    const Scene s = parse_scene("image width=100 height=100\ncamera eye=1,2,3 look=11,2,3 up=0,1,0.2 fov=60\n"
                                "sphere\nlight point pos=0,5,5\n", "cam.cfg");
    const auto cam = CameraRays<double>::from(s);
    CHECK(cam.origin.x == doctest::Approx(1.0));
    CHECK(cam.origin.y == doctest::Approx(2.0));
    CHECK(cam.origin.z == doctest::Approx(3.0));
    check_dir(cam.direction(50, 50), {1, 0, 0});
    const double t = std::tan(M_PI / 6);  // half of 60 degrees
    // The screen's up is `up` made perpendicular to the view direction: (0, 1, 0.2) already is.
    const double k = t / std::sqrt(1.04);
    check_dir(cam.direction(50, 0), {1, k, 0.2 * k});
}

TEST_CASE("canonical camera form: homothety (rx, ry, df) then transforms, as the handout says") {
    // Eye (0,0,1) scaled by df = 2 then moved by (0,0,3): (0,0,5). Screen corner (-1,1,0)
    // scaled by (rx, ry) = (1, 0.5).
    const Scene s = parse_scene("image width=4 height=2\ncamera rx=1 ry=0.5 df=2 translate=0,0,3\n"
                                "sphere\nlight point pos=0,5,5\n", "cam.cfg");
    const auto cam = CameraRays<double>::from(s);
    CHECK(cam.origin.z == doctest::Approx(5.0));
    check_dir(cam.direction(2, 1), {0, 0, -1});
    check_dir(cam.direction(0, 0), {-1, 0.5, -2});
    check_dir(cam.direction(4, 2), {1, -0.5, -2});
}

TEST_CASE("canonical camera with a rotation: rotate_y=90 looks down -x") {
    const Scene s = parse_scene("image width=2 height=2\ncamera rotate_y=90 translate=5,0,0\n"
                                "sphere\nlight point pos=0,5,5\n", "cam.cfg");
    const auto cam = CameraRays<double>::from(s);
    // The eye (0,0,1) rotated about y by 90 degrees goes to (1,0,0), then moved to (6,0,0).
    CHECK(cam.origin.x == doctest::Approx(6.0));
    check_dir(cam.direction(1, 1), {-1, 0, 0});
}
