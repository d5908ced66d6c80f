// The weight cut-off (image cutoff= / --cutoff): a reflected or refracted ray whose
// throughput (the product of the refl / trans weights from the camera) is below the cut-off
// in every channel is not traced, by the same rule in both engines.
#include <doctest/doctest.h>

#include <cstdint>
#include <string>

#include "driver/render.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

/// A mirror floor (refl 0.5) under a red sky, no lights, ambient 1: every pixel sees the
/// floor (the view spans 30 to 60 degrees below the horizon) and its reflection sees the sky.
/// Exact colour: ambient alpha ambi Col = (0.2, 0.4, 0.6), plus refl x sky = 0.5 x (1, 0, 0)
/// when the reflected ray is traced.
Scene mirror_floor(const std::string& cutoff) {
    return parse_scene("image width=8 height=8 spp=1 degree=3 depth=5" + cutoff +
                           "\nambient 1\nbackground 1,0,0\ncamera eye=0,1,0 look=0,0,-1 up=0,1,0 fov=30\n"
                           "plane color=0.2,0.4,0.6 ambi=1 diff=0 refl=0.5\n",
                       "cutoff.cfg");
}

void check_every_pixel(const Framebuffer& fb, float r, float g, float b) {
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x) {
            CAPTURE(x);
            CAPTURE(y);
            CHECK(fb.pixel(x, y)[0] == doctest::Approx(r).epsilon(1e-6));
            CHECK(fb.pixel(x, y)[1] == doctest::Approx(g).epsilon(1e-6));
            CHECK(fb.pixel(x, y)[2] == doctest::Approx(b).epsilon(1e-6));
        }
}

}  // namespace

TEST_CASE("cut-off: a child below it is not traced, at it or above it is, in both engines") {
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        const std::string name = engine_name(engine);
        CAPTURE(name);
        Parallelism par(2);
        {
            const RenderResult exact = render_scene(mirror_floor(""), engine, par);  // default 0: all
            check_every_pixel(exact.image, 0.7f, 0.4f, 0.6f);
            CHECK(exact.counts.reflected == 64);
        }
        {
            const RenderResult at = render_scene(mirror_floor(" cutoff=0.5"), engine, par);  // 0.5 >= 0.5: traced
            check_every_pixel(at.image, 0.7f, 0.4f, 0.6f);
            CHECK(at.counts.reflected == 64);
        }
        {
            const RenderResult cut = render_scene(mirror_floor(" cutoff=0.6"), engine, par);
            check_every_pixel(cut.image, 0.2f, 0.4f, 0.6f);
            CHECK(cut.counts.reflected == 0);
        }
    }
}

TEST_CASE("cut-off: the stream engine's rule ignores the samples' 1/spp weight") {
    // At 4 spp each stream ray weighs 1/4: the cut-off still compares refl alone (0.5).
    Scene s = mirror_floor(" cutoff=0.5");
    s.settings.spp = 4;
    Parallelism par(2);
    const RenderResult r = render_scene(s, EngineKind::Stream, par);
    check_every_pixel(r.image, 0.7f, 0.4f, 0.6f);
    CHECK(r.counts.reflected == 256);
}

TEST_CASE("cut-off: adaptive sampling's samples are cut by refl alone too, in both engines") {
    // Adaptive samples each weigh 1 in a slot of their own (spp is the cap, 64): the stream
    // engine once scaled the cut-off by 1/64 for them as for uniform samples, and traced the
    // 0.5 children a cut-off of 0.6 leaves out. The flat floor stops at its 9 x 9 corners.
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        const std::string name = engine_name(engine);
        CAPTURE(name);
        Parallelism par(2);
        struct Case {
            const char* cutoff;
            std::uint64_t reflected;
            float red;  // 0.2 ambient, + 0.5 of the red sky when the reflection is traced
        };
        for (const Case c : {Case{" cutoff=0.6", 0, 0.2f}, Case{" cutoff=0.5", 81, 0.7f}}) {
            CAPTURE(c.cutoff);
            Scene s = mirror_floor(c.cutoff);
            s.settings.spp = 64;
            s.settings.adaptive = 0.01;
            const RenderResult r = render_scene(s, engine, par);
            REQUIRE(r.adaptive);
            CHECK(r.counts.primary == 81);
            CHECK(r.counts.reflected == c.reflected);
            check_every_pixel(r.image, c.red, 0.4f, 0.6f);
        }
    }
}

TEST_CASE("cut-off: out of [0, 1] is a scene error at the value") {
    try {
        (void)parse_scene("image cutoff=1.5\n", "bad.cfg");
        FAIL("accepted cutoff=1.5");
    } catch (const SceneError& e) {
        CHECK(std::string(e.what()).rfind("bad.cfg:1:14:", 0) == 0);
    }
}
