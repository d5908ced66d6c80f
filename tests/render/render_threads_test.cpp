// In-process renders on several threads (what ThreadSanitizer checks in scripts/sanitize.sh
// tsan): both engines, -j1 and -j2 give the same picture, and a cancelled render stops.
#include <doctest/doctest.h>

#include <atomic>

#include "parallel/parallelism.h"
#include "driver/render.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {
const char* kScene =
    "image width=40 height=30 spp=2 depth=3 degree=5\n"
    "camera eye=0,1,6 look=0,0,0\n"
    "light point pos=5,8,5\nlight directional dir=0,-1,-1\n"
    "sphere refl=0.3 trans=0.5 ior=1.5\ncube translate=2,0,0 scale=0.5\nplane translate=0,-1,0 checker=0,0,0\n";
}

TEST_CASE("render threads: -j1 and -j2 give the same image with both engines") {
    const Scene sc = parse_scene(kScene, "t.cfg");
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        Parallelism one(1), two(2);
        const RenderResult a = render_scene(sc, engine, one);
        const RenderResult b = render_scene(sc, engine, two);
        CHECK(a.image.rgb == b.image.rgb);
        CHECK(a.counts.total() == b.counts.total());
    }
}

TEST_CASE("render threads: a cancelled render stops early") {
    const Scene sc = parse_scene(kScene, "t.cfg");
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        std::atomic<bool> cancel{true};
        RenderProgress progress;
        progress.cancel = &cancel;
        Parallelism two(2);
        const RenderResult r = render_scene(sc, engine, two, &progress);
        CHECK(r.counts.total() == 0);
    }
}

TEST_CASE("render threads: both engines report every tile the progress display counts") {
    // The display's total (tile_count) and the engines' tiles must be the same tiles, or the
    // bar never reaches 100 % (48x33 at 16: 3 x 3 tiles; another size would count otherwise).
    Scene s = parse_scene(kScene, "t.cfg");
    s.settings.width = 48;
    s.settings.height = 33;
    CHECK(tile_count(48, 33) == 9);
    for (EngineKind e : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(e));
        Parallelism par(2);
        RenderProgress progress;
        render_scene(s, e, par, &progress);
        CHECK(progress.tiles_done.load() == tile_count(s.settings.width, s.settings.height));
    }
}
