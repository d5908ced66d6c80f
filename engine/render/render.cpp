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
    const auto start = std::chrono::steady_clock::now();
    RenderResult r;
    if (engine == EngineKind::Recursive) {
        RecursiveRenderer renderer(scene);
        r.image = renderer.render(par, &p);
    } else {
        StreamRenderer renderer(scene, options.isa, options.scalar_shade);
        r.image = renderer.render(par, &p, options.profile);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.counts = p.counts();
    return r;
}

}  // namespace streamrt
