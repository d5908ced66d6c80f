#include "render/render.h"

#include <chrono>

#include "baseline/recursive_renderer.h"
#include "stream/stream_renderer.h"

namespace streamrt {

const char* engine_name(EngineKind e) { return e == EngineKind::Stream ? "stream" : "recursive"; }

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par, RenderProgress* progress,
                          const EngineOptions& options) {
    RenderProgress local;
    RenderProgress& p = progress ? *progress : local;
    using Clock = std::chrono::steady_clock;
    const auto seconds_since = [](Clock::time_point t) {
        return std::chrono::duration<double>(Clock::now() - t).count();
    };
    // Set-up (the engine's tables, the object hierarchy) and rendering are timed apart, so
    // that rays/s speaks of the rendering alone.
    RenderResult r;
    auto start = Clock::now();
    if (engine == EngineKind::Recursive) {
        RecursiveRenderer renderer(scene);
        r.setup_seconds = seconds_since(start);
        start = Clock::now();
        r.image = renderer.render(par, &p);
    } else {
        StreamRenderer renderer(scene, options.isa, options.scalar_shade);
        r.setup_seconds = seconds_since(start);
        start = Clock::now();
        r.image = renderer.render(par, &p, options.profile);
    }
    r.seconds = seconds_since(start);
    r.counts = p.counts();
    return r;
}

}  // namespace streamrt
