// Animation through the engines: a keyed sphere covers, at each frame, exactly the pixels the
// closed form says, and a set-up updated from frame to frame (refitted or rebuilt hierarchy,
// flat tables) gives the same picture, float for float, as a set-up made at that frame.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "driver/render.h"
#include "image/image_compare.h"
#include "scene/animation.h"
#include "scene/parser.h"
#include "scene/scene_bvh.h"

using namespace streamrt;

namespace {

Framebuffer render(PreparedRender& p) {
    Parallelism par(2);
    return render_prepared(p, par).image;
}

bool same_pixels(const Framebuffer& a, const Framebuffer& b) {
    return a.width == b.width && a.height == b.height && a.rgb == b.rgb;
}

}  // namespace

TEST_CASE("animation: a keyed sphere covers the pixels of its interpolated place") {
    // The canonical camera (eye (0,0,1), screen [-1,1] in z = 0), one row of 64 pixels at
    // y = 0. The sphere (radius 0.2) moves from x = -0.6 to x = 0.6 at z = -1 over frames
    // 0..10. The ray through screen point (xs, 0, 0) passes at distance
    // |2 xs - cx| / sqrt(xs^2 + 1) from the centre (cx, 0, -1): covered when that is < 0.2.
    const std::string text =
        "image width=64 height=1 spp=1 degree=0\n"
        "sphere name=b color=1,1,1 scale=0.2\n"
        "key b frame=0 translate=-0.6,0,-1\n"
        "key b frame=10 translate=0.6,0,-1\n";
    for (const EngineKind engine : {EngineKind::Recursive, EngineKind::Stream}) {
        CAPTURE(std::string(engine_name(engine)));
        Scene scene = parse_scene(text, "t.cfg");
        const auto prepared = prepare_render(scene, engine);
        for (const int frame : {3, 5, 10, 12}) {
            CAPTURE(frame);
            prepared->update(scene, set_frame(scene, frame));
            const Framebuffer img = render(*prepared);
            const double cx = -0.6 + 1.2 * std::min(frame, 10) / 10.0;
            int covered = 0;
            for (int i = 0; i < 64; ++i) {
                const double xs = -1.0 + (2.0 * i + 1.0) / 64.0;
                const double margin = std::abs(2.0 * xs - cx) / std::sqrt(xs * xs + 1.0) - 0.2;
                if (std::abs(margin) < 1e-4) continue;  // on the silhouette: either is right
                CAPTURE(i);
                CHECK((img.pixel(i, 0)[0] > 0.5f) == (margin < 0));
                covered += margin < 0;
            }
            CHECK(covered >= 5);  // the sphere is on the row (some 6 pixels wide)
        }
    }
}

TEST_CASE("animation: per-frame update (refit, rebuild, flat) equals a set-up made at the frame") {
    // 300 spheres on a grid with jitter, 3 keyed, a keyed light, and in two of the modes a
    // keyed camera (the stream engine renders relative to the eye: every record moves then).
    std::string text =
        "image width=48 height=36 spp=1 depth=2 degree=5\n"
        "camera name=cam eye=0,12,30 look=0,0,0\n"
        "light point name=l pos=10,20,10\n"
        "plane color=0.8,0.8,0.8\n";
    std::uint32_t h = 12345;
    const auto rnd = [&h] {
        h = h * 1664525u + 1013904223u;
        return double(h >> 8) / double(1u << 24);
    };
    for (int i = 0; i < 300; ++i) {
        const double x = -15 + (i % 20) * 1.5 + 0.4 * rnd(), z = -15 + (i / 20) * 2.0 + 0.4 * rnd();
        text += "sphere" + std::string(i % 100 == 7 ? " name=s" + std::to_string(i) : "") + " color=" +
                std::to_string(rnd()) + ",0.5,0.5 scale=0.5 translate=" + std::to_string(x) + ",0.5," +
                std::to_string(z) + "\n";
    }
    text += "key s7 frame=0 translate=0,0,0\nkey s7 frame=8 translate=3,4,-2 rotate=1,0,0,30\n";
    text += "key s107 frame=2 scale=1\nkey s107 frame=6 scale=2\n";
    text += "key s207 frame=0 translate=0,0,0\nkey s207 frame=8 translate=-20,0,0\n";

    struct Mode {
        const char* name;
        accel::AccelMode mode;
        double share;
        bool camera;
    };
    for (const Mode m : {Mode{"bvh refit", accel::AccelMode::Bvh, 1.0, false},
                         Mode{"bvh rebuild", accel::AccelMode::Bvh, 0.0, false},
                         Mode{"bvh, camera moving", accel::AccelMode::Bvh, 0.25, true},
                         Mode{"flat", accel::AccelMode::Flat, 0.25, true}}) {
        CAPTURE(m.name);
        EngineOptions options;
        options.accel.mode = m.mode;
        options.accel.refit_max_share = m.share;
        const std::string scene_text = text + "key l frame=0 pos=10,20,10\nkey l frame=8 pos=-10,20,10\n" +
                                       (m.camera ? "key cam frame=0 eye=0,12,30\nkey cam frame=8 eye=12,10,26\n" : "");
        for (const EngineKind engine : {EngineKind::Recursive, EngineKind::Stream}) {
            CAPTURE(std::string(engine_name(engine)));
            Scene animated = parse_scene(scene_text, "t.cfg");
            const auto updated = prepare_render(animated, engine, options);
            for (const int frame : {1, 4, 7}) {
                CAPTURE(frame);
                const FrameChange change = set_frame(animated, frame);
                CHECK(change.objects.size() >= 1);
                updated->update(animated, change);
                Scene fresh = parse_scene(scene_text, "t.cfg");
                set_frame(fresh, frame);
                const auto made = prepare_render(fresh, engine, options);
                CHECK(same_pixels(render(*updated), render(*made)));
            }
        }
    }
}

TEST_CASE("animation: the hierarchy is refitted until a quarter of its objects moved since its build") {
    std::string text;
    for (int i = 0; i < 100; ++i) text += "sphere scale=0.4 translate=" + std::to_string(i) + ",0,0\n";
    text += "plane\n";  // unbounded: not counted
    Scene scene = parse_scene(text, "t.cfg");
    accel::AccelConfig config;
    config.refit_max_share = 0.25;
    const auto bvh = accel::SceneBvh::build(scene);
    CHECK(bvh->bounded == 100);
    CHECK(bvh->refit_pays(25, config));
    CHECK(!bvh->refit_pays(26, config));
    // 20 moved (and refitted): 5 more still pay, 6 more do not.
    std::vector<std::uint32_t> moved;
    for (std::uint32_t i = 0; i < 20; ++i) moved.push_back(i);
    for (const std::uint32_t i : moved) scene.objects[i].md[3].y += 1.0;
    bvh->refit(scene, moved, bvh->bvh.prim_index);
    CHECK(bvh->refit_pays(5, config));
    CHECK(!bvh->refit_pays(6, config));
    // The refitted boxes hold the moved spheres: the root's box reaches y = 1.4.
    CHECK(bvh->bvh.bounds.hi[1] >= 1.4f);
    CHECK(bvh->bvh.bounds.hi[1] < 1.41f);
}

TEST_CASE("animation: the stream engine agrees with the baseline on frames of scenes/anim/orbit.cfg") {
    // Frame 0 is in the every-scene comparison (tests/stream/stream_engine_test.cpp); here the
    // frames where the ball is up, squashed and the camera half-way round.
    Scene scene = load_scene(std::string(STREAMRT_SOURCE_DIR) + "/scenes/anim/orbit.cfg");
    scene.settings.width = 160;
    scene.settings.height = 120;
    const auto stream = prepare_render(scene, EngineKind::Stream);
    const auto base = prepare_render(scene, EngineKind::Recursive);
    for (const int frame : {6, 13, 23}) {
        CAPTURE(frame);
        const FrameChange change = set_frame(scene, frame);
        stream->update(scene, change);
        base->update(scene, change);
        const ImageDifference d = compare_images(render(*stream), render(*base));
        CHECK(d.psnr >= 50.0);
        CHECK(d.share_over <= 0.001);
    }
}
