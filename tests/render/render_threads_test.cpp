// In-process renders on several threads (what ThreadSanitizer checks in scripts/sanitize.sh
// tsan): both engines, -j1 and -j2 give the same picture, and a cancelled render stops.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <vector>

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

TEST_CASE("render threads: a render cancelled before it starts renders nothing") {
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

// Proven against: render_tiles ignoring the flag (its checks after source() and after
// render_tile both removed: tile 3 and later are delivered, blank, and every tile is pulled).
// Either check alone stops the loop, and the engines poll the flag too, so one removed check
// changes nothing this test can see.
TEST_CASE("render threads: a render cancelled while it runs stops, delivering only tiles finished before") {
    // 256x256: 256 tiles. The tile source raises the cancel flag when it is asked for the 4th
    // tile (index 3), as Ctrl-C would between tiles. No clock: what may still happen after the
    // flag follows from the loop's structure alone, whatever the threads' speed.
    Scene sc = parse_scene(kScene, "t.cfg");
    sc.settings.width = 256;
    sc.settings.height = 256;
    const int total = tile_count(256, 256);
    REQUIRE(total == 256);
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(engine));
        const auto prepared = prepare_render(sc, engine);
        // The reference pixels of the first tiles, rendered alone.
        std::vector<std::vector<float>> reference(4);
        for (int i = 0; i < 4; ++i) {
            const Tile t = tile_rect(256, 256, i);
            reference[std::size_t(i)].resize(std::size_t(t.width() * t.height() * 3));
            RayCounts c;
            prepared->render_tile(t, reference[std::size_t(i)].data(), c, nullptr);
        }
        for (int jobs : {1, 2}) {
            CAPTURE(jobs);
            std::atomic<bool> cancel{false};
            RenderProgress progress;
            progress.cancel = &cancel;
            std::atomic<int> requests{0};
            const TileSource source = [&] {
                const int i = requests.fetch_add(1);
                if (i == 3) cancel = true;
                return i < total ? i : -1;
            };
            std::mutex m;
            std::vector<int> delivered;
            const TileSink sink = [&](const TileOutput& out) {
                const std::size_t n = std::size_t(out.tile.width() * out.tile.height() * 3);
                const std::lock_guard<std::mutex> lock(m);
                delivered.push_back(out.index);
                CHECK(out.index < 3);  // tile 3 and later were handed out after the flag
                if (out.index < 3)
                    CHECK(std::equal(out.rgb, out.rgb + n, reference[std::size_t(out.index)].begin()));
            };
            Parallelism par(jobs);
            render_tiles(*prepared, par, source, sink, &progress);
            // Each worker asks once more after the flag, sees it and stops.
            CHECK(requests.load() <= 3 + jobs);
            CHECK(delivered.size() <= 3);
            CHECK(progress.tiles_done.load() == int(delivered.size()));
            if (jobs == 1) CHECK(delivered.size() == 3);  // one worker finished tiles 0-2 before asking
        }
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
