#include "driver/render.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <utility>

#include "baseline/recursive_renderer.h"
#include "driver/adaptive_render.h"
#include "stream/stream_renderer.h"

namespace streamrt {

const char* engine_name(EngineKind e) { return name_of(kEngineNames, e).data(); }  // the literals end in NUL

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// A scene the caller keeps alive: a shared pointer that owns nothing.
std::shared_ptr<const Scene> borrowed(const Scene& scene) {
    return std::shared_ptr<const Scene>(std::shared_ptr<const Scene>(), &scene);
}

class PreparedRecursive final : public PreparedRender {
  public:
    PreparedRecursive(std::shared_ptr<const Scene> scene, const RenderSettings& settings, const EngineOptions& options)
        : scene_(std::move(scene)), renderer_(*scene_, settings, options.accel) {}
    bool reads_scene_objects() const override { return true; }
    void render_samples(const Tile& tile, SampleRun run, const std::uint32_t* pixels, int n_pixels, float* out,
                        RayCounts& counts, const RenderProgress* cancel) override {
        for (int i = 0; i < n_pixels; ++i) {
            if (cancel && cancel->cancelled()) return;
            const int x = tile.x0 + int(pixels[i]) % tile.width(), y = tile.y0 + int(pixels[i]) / tile.width();
            for (int j = 0; j < run.count; ++j, out += 3) {
                const ColorT<double> c = renderer_.render_sample(x, y, run, j, counts);
                out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
            }
        }
    }

  protected:
    Framebuffer render_uniform(Parallelism& par, RenderProgress* progress) override {
        return renderer_.render(par, progress);
    }
    void update_engine(std::shared_ptr<const Scene> scene, const FrameChange& change) override {
        renderer_.update(*scene, change);
        scene_ = std::move(scene);  // the frame before is let go once the renderer reads this one
    }
    void render_uniform_tile(const Tile& tile, float* rgb, RayCounts& counts, const RenderProgress* cancel) override {
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                if (cancel && cancel->cancelled()) return;
                const ColorT<double> c = renderer_.render_pixel(x, y, counts);
                float* px = rgb + (std::size_t(y - tile.y0) * std::size_t(tile.width()) + std::size_t(x - tile.x0)) * 3;
                px[0] = float(c.x);
                px[1] = float(c.y);
                px[2] = float(c.z);
            }
    }

  private:
    std::shared_ptr<const Scene> scene_;  ///< the scene renderer_ reads: declared first, destroyed last
    RecursiveRenderer renderer_;
};

class PreparedStream final : public PreparedRender {
  public:
    PreparedStream(const Scene& scene, const RenderSettings& settings, const EngineOptions& options)
        : renderer_(scene, settings, options.isa, options.shade, options.slice_rays, options.accel),
          profile_(options.profile) {}
    bool reads_scene_objects() const override { return false; }
    void render_samples(const Tile& tile, SampleRun run, const std::uint32_t* pixels, int n_pixels, float* out,
                        RayCounts& counts, const RenderProgress* cancel) override {
        profiled(counts, [&](RayCounts& c, StreamProfile* p) {
            renderer_.render_samples(tile, run, pixels, n_pixels, out, c, p, cancel);
        });
    }
    void finish_tiles(double wall_seconds, int threads) override {
        if (profile_) renderer_.describe(*profile_, wall_seconds, threads);
    }

  protected:
    Framebuffer render_uniform(Parallelism& par, RenderProgress* progress) override {
        return renderer_.render(par, progress, profile_);
    }
    void update_engine(std::shared_ptr<const Scene> scene, const FrameChange& change) override {
        renderer_.update(*scene, change);  // converted: the scene is not kept
    }
    void render_uniform_tile(const Tile& tile, float* rgb, RayCounts& counts, const RenderProgress* cancel) override {
        profiled(counts, [&](RayCounts& c, StreamProfile* p) { renderer_.render_one_tile(tile, rgb, c, p, cancel); });
    }

  private:
    /// Runs work(counts, profile): with a profile, into a local one merged under the lock.
    template <class Work>
    void profiled(RayCounts& counts, Work&& work) {
        if (!profile_) return work(counts, nullptr);
        StreamProfile local;
        RayCounts c;
        work(c, &local);
        counts += c;
        std::lock_guard<std::mutex> lock(mutex_);
        *profile_ += local;
        profile_->counts += c;
    }

    StreamRenderer renderer_;
    StreamProfile* profile_;
    std::mutex mutex_;
};

}  // namespace

std::unique_ptr<PreparedRender> prepare_render(std::shared_ptr<const Scene> scene, const RenderSettings& settings,
                                               EngineKind engine, const EngineOptions& options) {
    // Set-up (the engine's tables, the object hierarchy) and rendering are timed apart, so
    // that rays/s speaks of the rendering alone.
    const auto start = Clock::now();
    std::unique_ptr<PreparedRender> p;
    if (engine == EngineKind::Recursive) p = std::make_unique<PreparedRecursive>(std::move(scene), settings, options);
    else p = std::make_unique<PreparedStream>(*scene, settings, options);
    p->setup_seconds = seconds_since(start);
    p->width = settings.width;
    p->height = settings.height;
    p->adaptive = AdaptiveRule{settings.adaptive, settings.spp};
    p->stop = options.adaptive_stop;
    p->keep_sample_map = options.sample_map;
    return p;
}

std::unique_ptr<PreparedRender> prepare_render(const Scene& scene, EngineKind engine, const EngineOptions& options) {
    return prepare_render(borrowed(scene), scene.settings, engine, options);
}

Framebuffer PreparedRender::render(Parallelism& par, RenderProgress* progress) {
    if (!adaptive.on()) return render_uniform(par, progress);
    const auto start = Clock::now();
    Framebuffer image = render_adaptive_image(*this, par, progress);
    finish_tiles(seconds_since(start), par.jobs());
    return image;
}

void PreparedRender::render_tile(const Tile& tile, float* rgb, RayCounts& counts, const RenderProgress* cancel) {
    if (adaptive.on()) render_adaptive_tile(*this, tile, rgb, counts, cancel);
    else render_uniform_tile(tile, rgb, counts, cancel);
}

void PreparedRender::update(std::shared_ptr<const Scene> scene, const FrameChange& change) {
    const auto start = Clock::now();
    update_engine(std::move(scene), change);  // also without changes: the engine may hold the new scene
    setup_seconds = seconds_since(start);
}

void PreparedRender::update(const Scene& scene, const FrameChange& change) { update(borrowed(scene), change); }

void render_tiles(PreparedRender& prepared, Parallelism& par, const TileSource& source, const TileSink& sink,
                  RenderProgress* progress) {
    const auto start = Clock::now();
    // One task per thread, each pulling tiles until the source runs dry: the source decides
    // the order (a list, or a queue shared with other processes).
    par.for_each_index(std::size_t(par.jobs()), 1, [&](std::size_t) {
        float rgb[kTileSize * kTileSize * 3];
        for (int index = source(); index >= 0; index = source()) {
            if (progress && progress->cancelled()) return;
            TileOutput out;
            out.index = index;
            out.tile = tile_rect(prepared.width, prepared.height, index);
            out.rgb = rgb;
            const auto t0 = Clock::now();
            prepared.render_tile(out.tile, rgb, out.counts, progress);
            out.seconds = seconds_since(t0);
            if (progress && progress->cancelled()) return;
            sink(out);
            if (progress) progress->add(out.counts);
        }
    });
    prepared.finish_tiles(seconds_since(start), par.jobs());
}

void render_tiles(PreparedRender& prepared, Parallelism& par, std::span<const int> tiles, const TileSink& sink,
                  RenderProgress* progress) {
    std::atomic<std::size_t> next{0};
    const auto source = [&] {
        const std::size_t i = next.fetch_add(1);
        return i < tiles.size() ? tiles[i] : -1;
    };
    render_tiles(prepared, par, source, sink, progress);
}

RenderResult render_prepared(PreparedRender& prepared, Parallelism& par, RenderProgress* progress) {
    RenderProgress local;
    RenderProgress& p = progress ? *progress : local;
    RenderResult r;
    r.setup_seconds = prepared.setup_seconds;
    const auto start = Clock::now();
    r.image = prepared.render(par, &p);
    r.seconds = seconds_since(start);
    r.adaptive = prepared.last_adaptive;
    if (r.adaptive) r.sample_map = std::move(prepared.sample_map);  // the result owns it from here
    r.counts = p.counts();
    return r;
}

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par, RenderProgress* progress,
                          const EngineOptions& options) {
    const auto prepared = prepare_render(scene, engine, options);
    return render_prepared(*prepared, par, progress);
}

}  // namespace streamrt
