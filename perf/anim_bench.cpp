// Per-frame set-up of an animated scene (docs/performance.md, "## Animation"): N random
// spheres, K of them keyed, frames 1..F. For each engine, the per-frame update with the
// hierarchy refitted, with it rebuilt, and a whole new set-up per frame (what rendering each
// frame as its own scene costs), each the median over the frames; then the render time of
// the last frame (320x240) with the refitted and with the rebuilt hierarchy.
//   anim_bench [N=100000] [K=1] [F=10] [jobs=0]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "driver/render.h"
#include "scene/animation.h"
#include "scene/parser.h"
#include "scene/scene_bvh.h"

using namespace streamrt;

namespace {

std::string make_scene(int n, int keyed) {
    std::string text = "image width=320 height=240 spp=1 degree=5\ncamera eye=0,40,120 look=0,0,0\n"
                       "light point pos=50,100,50\nplane color=0.8,0.8,0.8\n";
    std::uint32_t h = 7;
    const auto rnd = [&h] {
        h = h * 1664525u + 1013904223u;
        return double(h >> 8) / double(1u << 24);
    };
    char line[256];
    for (int i = 0; i < n; ++i) {
        std::snprintf(line, sizeof line, "sphere%s color=%.3f,0.5,0.5 scale=0.3 translate=%.3f,%.3f,%.3f\n",
                      i < keyed ? (" name=s" + std::to_string(i)).c_str() : "", rnd(), -50 + 100 * rnd(),
                      0.3 + 20 * rnd(), -50 + 100 * rnd());
        text += line;
    }
    for (int i = 0; i < keyed; ++i)
        text += "key s" + std::to_string(i) + " frame=0 translate=0,0,0\nkey s" + std::to_string(i) +
                " frame=100 translate=30,10,-20 rotate=0,1,0,90\n";
    return text;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 100000;
    const int keyed = argc > 2 ? std::atoi(argv[2]) : 1;
    const int frames = argc > 3 ? std::atoi(argv[3]) : 10;
    Parallelism par(argc > 4 ? std::atoi(argv[4]) : 0);
    const std::string text = make_scene(n, keyed);
    EngineOptions options;
    options.accel.mode = accel::AccelMode::Bvh;
    std::printf("%d spheres, %d keyed, frames 1..%d, %d threads; per-frame set-up, median (ms)\n", n, keyed, frames,
                par.jobs());
    std::printf("| engine | refit (first frame: links built) | rebuild | new set-up per frame | render, refitted | render, rebuilt |\n"
                "| --- | --- | --- | --- | --- | --- |\n");
    par.run([&] {
        for (const EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
            double ms[3], first_refit = 0, render_ms[2] = {0, 0};
            for (int how = 0; how < 3; ++how) {
                options.accel.refit_max_share = how == 0 ? 1e18 : 0.0;  // always refit / always rebuild
                Scene scene = parse_scene(text, "anim_bench");
                auto prepared = prepare_render(scene, engine, options);
                std::vector<double> t;
                for (int f = 1; f <= frames; ++f) {
                    const FrameChange change = set_frame(scene, f);
                    if (how < 2) {
                        prepared->update(scene, change);
                        t.push_back(prepared->setup_seconds);
                    } else {
                        prepared.reset();
                        prepared = prepare_render(scene, engine, options);
                        t.push_back(prepared->setup_seconds);
                    }
                }
                ms[how] = 1e3 * median(t);
                if (how < 2) {
                    std::vector<double> r;
                    for (int k = 0; k < 3; ++k) r.push_back(render_prepared(*prepared, par).seconds);
                    render_ms[how] = 1e3 * median(r);
                }
                if (how == 0) first_refit = 1e3 * t.front();
            }
            std::printf("| %s | %.3f (%.2f) | %.1f | %.1f | %.1f | %.1f |\n", engine_name(engine), ms[0], first_refit,
                        ms[1], ms[2], render_ms[0], render_ms[1]);
        }
        return 0;
    });
    return 0;
}
