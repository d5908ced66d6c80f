// A named csg block keyed like an object (docs/scene-format.md, "Animation" and "CSG"): its
// shapes move together, the recursive engine follows a frame change, and the reader's
// refusals.
#include <doctest/doctest.h>

#include <limits>
#include <memory>
#include <string>

#include "baseline/recursive_renderer.h"
#include "driver/render.h"
#include "parallel/parallelism.h"
#include "scene/animation.h"
#include "scene/expect_error.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A pipe (radius 1 minus radius 0.8, height 4) keyed to slide 3 along x over frames 0 - 10.
const char* const kSlidingPipe =
    "csg difference name=pipe\n"
    "  cylinder scale=1,2,1\n"
    "  cylinder scale=0.8,2.1,0.8\n"
    "end\n"
    "key pipe frame=0 translate=0,0,0\n"
    "key pipe frame=10 translate=3,0,0\n";

bool hits(const RecursiveRenderer& r, double x, HitD& hit) {
    return r.closest_hit(RayD{{x, 10, 0}, {0, -1, 0}}, 0.0, kInf, hit);
}

}  // namespace

TEST_CASE("csg animation: a keyed block moves all its shapes, and the engine follows") {
    const auto base = std::make_shared<const Scene>(parse_scene(kSlidingPipe, "t.cfg"));
    REQUIRE(base->animation);
    REQUIRE(base->animation->csg.size() == 1);
    const auto mid = scene_at_frame(base, 5);
    // Both cylinders moved by 1.5 along x; the scene as read did not.
    CHECK(mid->csg_shapes[0].md[3][0] == doctest::Approx(1.5));
    CHECK(mid->csg_shapes[1].md[3][0] == doctest::Approx(1.5));
    CHECK(base->csg_shapes[1].md[3][0] == 0.0);
    const FrameChange change = frame_change(*base->animation, 0, 5);
    REQUIRE(change.csg.size() == 1);
    CHECK(change.csg[0] == 0);
    CHECK(change.objects.empty());

    // The engine set up at frame 0: the rim's annulus at x = 0.9 is hit (top cap, y = 2), the
    // axis goes down the hole. Moved to frame 5, the same lines see the hole's wall region
    // shifted: x = 0.9 is now inside the hole (0.9 - 1.5 = -0.6), x = 1.5 + 0.9 on the rim.
    RecursiveRenderer r(*base);
    HitD hit;
    REQUIRE(hits(r, 0.9, hit));
    CHECK(hit.t == doctest::Approx(8.0));
    CHECK(!hits(r, 0.0, hit));
    r.update(*mid, change);
    CHECK(!hits(r, 0.9, hit));
    REQUIRE(hits(r, 2.4, hit));
    CHECK(hit.t == doctest::Approx(8.0));
    CHECK(!hits(r, 1.5, hit));
    // Past the last key the block holds there: x = 3 is the hole, x = 3.9 the rim.
    const auto last = scene_at_frame(base, 20);
    const RecursiveRenderer at_end(*last);
    CHECK(!hits(at_end, 3.0, hit));
    CHECK(hits(at_end, 3.9, hit));
}

TEST_CASE("csg animation: the reader's refusals for named blocks") {
    using test::expect_error;
    expect_error("csg union\n  csg union name=inner\n    sphere\n  end\nend\n", 2, 13,
                 "a nested csg block takes no name= (the outermost block is the object)");
    expect_error("csg union name=a\n  sphere\nend\nkey a frame=0 pos=1,0,0\n", 4, 15,
                 "key: 'pos' does not fit the csg object 'a'");
    expect_error("sphere name=a\ncsg union name=a\n  sphere\nend\n", 2, 16, "name 'a' is already given to the object of line 1");
}

TEST_CASE("csg animation: both engines updated frame by frame render what a set-up made at the frame renders") {
    // A lit die-like block (a cube minus a sphere) turning and sliding in front of a floor, the
    // camera still (the stream engine's records move with the block, not with the eye) and
    // moving (with the eye too).
    const std::string block =
        "image width=40 height=30 spp=1 degree=5\nlight point pos=3,6,5\nplane translate=0,-1.5,0\n"
        "csg difference name=die color=0.9,0.6,0.2\n  cube\n  sphere scale=1.3 color=0.2,0.4,0.9\nend\n"
        "key die frame=0 translate=-1,0,0\nkey die frame=8 translate=1,0.3,0 rotate=0,1,0,60\n";
    for (const bool camera_moves : {false, true}) {
        const std::string text = "camera name=cam eye=0,2,6 look=0,0,0 fov=45\n" + block +
                                 (camera_moves ? "key cam frame=0 eye=0,2,6\nkey cam frame=8 eye=2,2,5.5\n" : "");
        for (const EngineKind engine : {EngineKind::Recursive, EngineKind::Stream}) {
            CAPTURE(camera_moves);
            CAPTURE(std::string(engine_name(engine)));
            Scene animated = parse_scene(text, "t.cfg");
            const auto updated = prepare_render(animated, engine);
            for (const int frame : {3, 8}) {
                CAPTURE(frame);
                const FrameChange change = set_frame(animated, frame);
                REQUIRE(change.csg.size() == 1);
                updated->update(animated, change);
                Scene fresh = parse_scene(text, "t.cfg");
                set_frame(fresh, frame);
                const auto made = prepare_render(fresh, engine);
                Parallelism par(2);
                const Framebuffer a = render_prepared(*updated, par).image, b = render_prepared(*made, par).image;
                CHECK(a.rgb == b.rgb);
                // The block did move: frame 0's picture differs.
                Scene first = parse_scene(text, "t.cfg");
                const auto at0 = prepare_render(first, engine);
                CHECK(render_prepared(*at0, par).image.rgb != a.rgb);
            }
        }
    }
}
