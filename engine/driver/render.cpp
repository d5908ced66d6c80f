#include "driver/render.h"

#include <chrono>

#include "baseline/recursive_renderer.h"
#include "stream/stream_renderer.h"

namespace streamrt {

const char* engine_name(EngineKind e) { return e == EngineKind::Stream ? "stream" : "recursive"; }

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

class PreparedRecursive final : public PreparedRender {
  public:
    explicit PreparedRecursive(const Scene& scene) : renderer_(scene) {}
    Framebuffer render(Parallelism& par, RenderProgress* progress) override { return renderer_.render(par, progress); }
    bool reads_scene_objects() const override { return true; }

  private:
    RecursiveRenderer renderer_;
};

class PreparedStream final : public PreparedRender {
  public:
    PreparedStream(const Scene& scene, const EngineOptions& options)
        : renderer_(scene, options.isa, options.shade, options.slice_rays), profile_(options.profile) {}
    Framebuffer render(Parallelism& par, RenderProgress* progress) override {
        return renderer_.render(par, progress, profile_);
    }
    bool reads_scene_objects() const override { return false; }

  private:
    StreamRenderer renderer_;
    StreamProfile* profile_;
};

}  // namespace

std::unique_ptr<PreparedRender> prepare_render(const Scene& scene, EngineKind engine, const EngineOptions& options) {
    // Set-up (the engine's tables, the object hierarchy) and rendering are timed apart, so
    // that rays/s speaks of the rendering alone.
    const auto start = Clock::now();
    std::unique_ptr<PreparedRender> p;
    if (engine == EngineKind::Recursive) p = std::make_unique<PreparedRecursive>(scene);
    else p = std::make_unique<PreparedStream>(scene, options);
    p->setup_seconds = seconds_since(start);
    return p;
}

RenderResult render_prepared(PreparedRender& prepared, Parallelism& par, RenderProgress* progress) {
    RenderProgress local;
    RenderProgress& p = progress ? *progress : local;
    RenderResult r;
    r.setup_seconds = prepared.setup_seconds;
    const auto start = Clock::now();
    r.image = prepared.render(par, &p);
    r.seconds = seconds_since(start);
    r.counts = p.counts();
    return r;
}

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par, RenderProgress* progress,
                          const EngineOptions& options) {
    const auto prepared = prepare_render(scene, engine, options);
    return render_prepared(*prepared, par, progress);
}

}  // namespace streamrt
