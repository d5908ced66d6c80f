#include "render/render.h"

#include <chrono>

#include "baseline/recursive_renderer.h"

namespace streamrt {

const char* engine_name(EngineKind e) { return e == EngineKind::Stream ? "stream" : "recursive"; }

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par, RenderProgress* progress) {
    RenderProgress local;
    RenderProgress& p = progress ? *progress : local;
    const auto start = std::chrono::steady_clock::now();
    RenderResult r;
    (void)engine;
    RecursiveRenderer renderer(scene);
    r.image = renderer.render(par, &p);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.counts = p.counts();
    return r;
}

}  // namespace streamrt
