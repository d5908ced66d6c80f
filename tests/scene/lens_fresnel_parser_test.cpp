// The depth-of-field camera keys (aperture=, focus=) and the material key fresnel=: values,
// defaults, and errors at the exact line:column.
#include <doctest/doctest.h>

#include <string>

#include "scene/expect_error.h"
#include "scene/parser.h"

using namespace streamrt;

using test::expect_error;  // scene/expect_error.h

TEST_CASE("parser: camera aperture and focus in both forms") {
    const Scene a = parse_scene("camera eye=0,0,5 look=0,0,0 aperture=0.2 focus=4\n", "t.cfg");
    CHECK(a.camera.look_at);
    CHECK(a.camera.aperture == 0.2);
    CHECK(a.camera.focus == 4.0);
    // The lens keys may come first: the first other key still chooses the form.
    const Scene b = parse_scene("camera aperture=0.1 eye=1,2,3 look=0,0,0\n", "t.cfg");
    CHECK(b.camera.look_at);
    CHECK(b.camera.focus_distance(b.camera.world_from_canonical(4, 4)) == doctest::Approx(std::sqrt(14.0)));
    const Scene c = parse_scene("camera focus=2.5 rx=2 df=3\n", "t.cfg");
    CHECK_FALSE(c.camera.look_at);
    CHECK(c.camera.aperture == 0.0);
    CHECK(c.camera.focus_distance(c.camera.world_from_canonical(4, 4)) == 2.5);
    const Scene d = parse_scene("camera aperture=0.3 df=3 rotate_y=30\n", "t.cfg");  // default: |Md (0,0,-1)|
    CHECK(d.camera.focus_distance(d.camera.world_from_canonical(4, 4)) == doctest::Approx(3.0));
    const Scene e = parse_scene("camera aperture=0.3\n", "t.cfg");  // alone: the canonical camera
    CHECK_FALSE(e.camera.look_at);
    CHECK(e.camera.focus_distance(e.camera.world_from_canonical(4, 4)) == 1.0);
}

TEST_CASE("parser: fresnel= on materials and shapes") {
    const Scene s = parse_scene("material glass trans=0.9 ior=1.5 fresnel=true\nsphere material=glass\n"
                                "sphere material=glass fresnel=false\nsphere trans=0.5\n",
                                "t.cfg");
    REQUIRE(s.objects.size() == 3);
    CHECK(s.material_of(s.objects[0]).fresnel);
    CHECK_FALSE(s.material_of(s.objects[1]).fresnel);
    CHECK_FALSE(s.material_of(s.objects[2]).fresnel);
    CHECK(s.objects[0].material != s.objects[1].material);  // fresnel tells materials apart
}

TEST_CASE("parser: lens and fresnel errors at line:column") {
    expect_error("camera eye=0,0,5 look=0,0,0 aperture=-1", 1, 38, "'aperture' must be >= 0");
    expect_error("camera focus=0", 1, 14, "'focus' must be > 0");
    expect_error("\ncamera rx=2 focus=-3", 2, 19, "'focus' must be > 0");
    expect_error("camera aperture=wide", 1, 17, "expected a number for 'aperture'");
    expect_error("camera focus=1e39", 1, 14, "'focus' must be at most 3.4e38");
    expect_error("camera aperture=0.1 eye=0,0,5 rx=2", 1, 31, "belongs to the explicit form");
    expect_error("sphere fresnel=maybe", 1, 16, "expected true or false for 'fresnel'");
    expect_error("material glass fresnel=yes", 1, 24, "expected true or false for 'fresnel'");
    expect_error("light point pos=0,0,0 fresnel=true", 1, 23, "unknown key 'fresnel'");
}
