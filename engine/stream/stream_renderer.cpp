#include "stream/stream_renderer.h"

#include <algorithm>
#include <array>
#include <utility>
#include <chrono>
#include <mutex>

#include "parallel/pixel_order.h"
#include "render/sampling.h"
#include "shapes/shapes.h"
#include "stream/stages.h"

namespace streamrt {

StreamRenderer::StreamRenderer(const Scene& scene, const RenderSettings& settings, Isa isa, ShadeMode shade,
                               std::size_t slice_rays, const accel::AccelConfig& accel)
    : scene_(scene, settings, accel),
      kernels_(kernel_table(isa)),
      tile_fn_(nullptr),
      shade_mode_(resolve_shade_mode(scene_, shade)),
      slice_rays_(slice_rays > 0 ? slice_rays : default_slice_rays(scene_.settings.spp)),
      z_order_(scene_.accel ? !scene_.has_meshes : scene_.has_meshes) {
    tile_fn_ = select_tile_fn();
}

std::vector<std::string> StreamRenderer::built_stages() const {
    const StreamFeatures& f = scene_.features;
    std::vector<std::string> b{std::string(f.jitter ? "generate(jittered" : "generate(centre") +
                               (f.lens ? ",lens)" : ")")};
    std::string kernels = "intersect[";
    bool first = true;
    for (int k = 0; k < kShapeKindCount; ++k)
        if (!scene_.groups[k].empty()) {
            (kernels += first ? "" : ",") += shape_kind_name(ShapeKind(k));
            first = false;
        }
    b.push_back(kernels + "]");
    if (scene_.csg)
        b.push_back("csg(simd spans, " + std::to_string(scene_.csg->object_count()) + " objects" +
                    (scene_.csg->view().tree ? ", hierarchy)" : ")"));
    const char* how = shade_mode_ == ShadeMode::Sorted     ? ",simd,sorted)"
                      : shade_mode_ == ShadeMode::Gathered ? ",simd,gathered)"
                                                           : ",scalar)";
    b.push_back(std::string(f.lighting ? "shade(lit" : "shade(flat") + (f.textures ? ",textured" : "") + how);
    if (f.reflect) b.push_back("spawn(reflect)");
    if (f.refract) b.push_back("spawn(refract)");
    if (f.bounce) b.push_back("spawn(diffuse)");
    if (f.shadows)
        b.push_back(f.area_lights ? "occlusion(any-hit,area x " + std::to_string(f.area_samples) + ")"
                                  : std::string("occlusion(any-hit)"));
    else if (f.area_lights)
        b.push_back("area lights x " + std::to_string(f.area_samples) + " (no shadows)");
    b.push_back("accumulate");
    return b;
}

template <bool kLighting, bool kShadows, bool kReflect, bool kRefract, bool kBounce, bool kJitter>
void StreamRenderer::render_tile(const StreamRenderer& self, const Tile& tile, const SampleRequest& req, float* accum,
                                 RayCounts& counts, StreamProfile* profile, const RenderProgress* cancel) {
    using Stages = PipelineStages<kLighting, kShadows, kReflect, kRefract, kBounce, kJitter>;
    const StreamScene& sc = self.scene_;
    // Memory in flight is bounded by the chunk, not the image: the request's pixels are cut
    // into chunks of whole pixels (all samples of a pixel in the same stream, hence packet).
    const int pixels_per_chunk = std::max(1, int(kMaxChunkRays / std::size_t(req.run.count)));
    static thread_local Workspace ws;
    for (int first = 0; first < req.n_pixels; first += pixels_per_chunk) {
        if (cancel && cancel->cancelled()) return;
        const int n_pixels = std::min(pixels_per_chunk, req.n_pixels - first);
        // Per-sample slots are counted from the chunk's first pixel.
        float* slots = req.per_sample ? accum + std::size_t(first) * std::size_t(req.run.count) * 3 : accum;
        Stages::run_chunk(sc, self.kernels_, tile, req, first, n_pixels, ws, slots, counts, profile, self.shade_mode_,
                          self.slice_rays_);
    }
}

StreamRenderer::TileFn StreamRenderer::select_tile_fn() const {
    // Every combination is instantiated; the scene picks one. A scene without lights or
    // mirrors runs a pipeline that has no code for them. Feature bits: lighting 1, shadows 2,
    // reflect 4, refract 8, jitter 16, bounce 32; bounces come with lighting only (degree 6),
    // so the unlit ones are not built.
    const StreamFeatures& f = scene_.features;
    const int key = (f.lighting ? 1 : 0) | (f.shadows ? 2 : 0) | (f.reflect ? 4 : 0) | (f.refract ? 8 : 0) |
                    (f.jitter ? 16 : 0) | (f.bounce ? 32 : 0);
    static constexpr auto pick = []<int k>() -> TileFn {
        if constexpr ((k & 32) && !(k & 1)) return nullptr;
        else return &render_tile<bool(k & 1), bool(k & 2), bool(k & 4), bool(k & 8), bool(k & 32), bool(k & 16)>;
    };
    static constexpr auto table = []<int... k>(std::integer_sequence<int, k...>) {
        return std::array<TileFn, sizeof...(k)>{pick.template operator()<k>()...};
    }(std::make_integer_sequence<int, 64>{});
    return table[std::size_t(key)];
}

void StreamRenderer::render_one_tile(const Tile& tile, float* rgb, RayCounts& counts, StreamProfile* profile,
                                     const RenderProgress* cancel) const {
    // Tile-local accumulation in a fixed order: the result cannot depend on scheduling.
    float accum[kTileSize * kTileSize * 3] = {};
    const int pixels = tile.width() * tile.height();
    // Pixels in Z order where rays walk one hierarchy (z_order_), whose nodes a compact packet
    // shares. The rest keep the rows (docs/performance.md, "Design choices", pixels in Z order): a scene of a
    // few shapes, tested ray by ray against each, gained nothing (its shade stage lost 2 - 4 %),
    // and in the object tree over instanced meshes compact packets reach small instances with
    // more lanes, past the single-ray hand-over's threshold (the 10,000-instance field's
    // intersect 1.15x). A whole tile reads the table itself; a partial one filters it.
    std::uint32_t order[kTileSize * kTileSize];
    SampleRequest all{.run = {0, scene_.settings.spp}, .n_pixels = pixels};
    if (z_order_) {
        const bool whole = tile.width() == kTileSize && tile.height() == kTileSize;
        all.pixels = whole ? kZOrder.pixel : order;
        if (!whole) all.n_pixels = z_order_pixels(tile, order);
    }
    tile_fn_(*this, tile, all, accum, counts, profile, cancel);
    StageTimer timer(profile ? &profile->stages[int(Stage::Accumulate)] : nullptr);
    std::copy_n(accum, pixels * 3, rgb);
    if (profile) profile->stages[int(Stage::Accumulate)].rays_in += std::uint64_t(pixels);
}

void StreamRenderer::render_samples(const Tile& tile, SampleRun run, const std::uint32_t* pixels, int n_pixels,
                                    float* out, RayCounts& counts, StreamProfile* profile,
                                    const RenderProgress* cancel) const {
    std::fill_n(out, std::size_t(n_pixels) * std::size_t(run.count) * 3, 0.f);
    const SampleRequest req{.run = run, .pixels = pixels, .n_pixels = n_pixels, .per_sample = true};
    tile_fn_(*this, tile, req, out, counts, profile, cancel);
    if (profile) profile->stages[int(Stage::Accumulate)].rays_in += std::uint64_t(n_pixels);
}

void StreamRenderer::describe(StreamProfile& profile, double wall_seconds, int threads) const {
    profile.wall_seconds = wall_seconds;
    profile.threads = threads;
    profile.isa = kernels_.name;
    profile.lanes = kernels_.float_lanes;
    profile.built = built_stages();
}

Framebuffer StreamRenderer::render(Parallelism& par, RenderProgress* progress, StreamProfile* profile) const {
    const RenderSettings& s = scene_.settings;
    Framebuffer fb = Framebuffer::uninitialized(s.width, s.height);  // every tile writes its pixels
    std::mutex profile_mutex;
    const auto start = std::chrono::steady_clock::now();
    par.for_each_tile(s.width, s.height, kTileSize, [&](int, Tile tile) {
        if (progress && progress->cancelled()) return;
        RayCounts counts;
        StreamProfile local;
        float rgb[kTileSize * kTileSize * 3];
        render_one_tile(tile, rgb, counts, profile ? &local : nullptr, progress);
        {
            StageTimer timer(profile ? &local.stages[int(Stage::Accumulate)] : nullptr);
            for (int y = tile.y0; y < tile.y1; ++y)
                std::copy_n(&rgb[((y - tile.y0) * tile.width()) * 3], tile.width() * 3, fb.pixel(tile.x0, y));
        }
        if (profile) {
            std::lock_guard<std::mutex> lock(profile_mutex);
            *profile += local;
            profile->counts += counts;
        }
        if (progress) progress->add(counts);
    });
    if (profile)
        describe(*profile, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), par.jobs());
    return fb;
}

}  // namespace streamrt
