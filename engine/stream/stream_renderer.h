#pragma once
// The ray-stream engine: rays in structure-of-arrays streams, processed breadth-first in
// stages per tile (generate, intersect, shade + spawn, occlusion, accumulate), with one SIMD
// kernel per canonical shape. Same pictures as the recursive baseline, in single precision.
#include <algorithm>
#include <cstddef>

#include "image/framebuffer.h"
#include "kernels/kernel_table.h"
#include "parallel/parallelism.h"
#include "render/render_stats.h"
#include "stream/profile.h"
#include "stream/sample_request.h"
#include "stream/shade_mode.h"
#include "stream/stream_scene.h"

namespace streamrt {

class StreamRenderer {
  public:
    /// shade: how the shade stage groups hits for its SIMD kernel (stream/shade_mode.h; Auto
    /// picks by object count, the others are kept for measurement and tests).
    /// slice_rays: the most rays of one generation traced at once per thread (0: the default,
    /// max(kSliceRays, spp)); smaller values are for tests.
    /// accel: whether and how the object hierarchy is used (EngineOptions::accel).
    /// settings: what is rendered (a render job's; the scene's own in the second form). The
    /// renderer keeps no reference to `scene` (StreamScene).
    StreamRenderer(const Scene& scene, const RenderSettings& settings, Isa isa, ShadeMode shade = ShadeMode::Auto,
                   std::size_t slice_rays = 0, const accel::AccelConfig& accel = {});
    StreamRenderer(const Scene& scene, Isa isa, ShadeMode shade = ShadeMode::Auto, std::size_t slice_rays = 0,
                   const accel::AccelConfig& accel = {})
        : StreamRenderer(scene, scene.settings, isa, shade, slice_rays, accel) {}

    /// Renders the image. With a profile, every stage is timed and counted into it.
    Framebuffer render(Parallelism& par, RenderProgress* progress = nullptr, StreamProfile* profile = nullptr) const;

    /// Renders one tile into `rgb` (tile.width() x tile.height() pixels, 3 floats each, row by
    /// row): the values render() gives those pixels, whichever thread or process runs it.
    /// With a profile, the stages are timed and counted into it.
    void render_one_tile(const Tile& tile, float* rgb, RayCounts& counts, StreamProfile* profile = nullptr,
                         const RenderProgress* cancel = nullptr) const;

    /// Traces samples `run` of the listed pixels of `tile` (tile-local numbers, row by row)
    /// and writes each sample's colour into `out`: 3 floats per sample, the samples of the
    /// first pixel in order, then the next pixel's (adaptive sampling, render/adaptive.h).
    void render_samples(const Tile& tile, SampleRun run, const std::uint32_t* pixels, int n_pixels, float* out,
                        RayCounts& counts, StreamProfile* profile = nullptr,
                        const RenderProgress* cancel = nullptr) const;

    /// Fills the profile's description of the run: wall time, threads, kernels and stages.
    void describe(StreamProfile& profile, double wall_seconds, int threads) const;

    /// Animation: `scene` is the scene at another frame (of the one this renderer was made
    /// for); only what `change` names is converted again (StreamScene::update).
    void update(const Scene& scene, const FrameChange& change) { scene_.update(scene, change); }

    /// Names of the stages and kernels this scene's pipeline is built from.
    std::vector<std::string> built_stages() const;

    /// Pixels per tile side, and the most primary rays in flight per tile chunk.
    static constexpr int kTileSize = streamrt::kTileSize;
    static constexpr std::size_t kMaxChunkRays = 4096;
    /// Generations are traced deepest first in slices of at most max(kSliceRays, spp) rays
    /// (stages.h, trace_generation): per thread, at most 2 x that many rays are held per
    /// generation reached, whatever the depth.
    static constexpr std::size_t kSliceRays = 16384;
    /// The slice size used for a scene with `spp` samples per pixel (slice_rays 0).
    static std::size_t default_slice_rays(int spp) { return std::max(kSliceRays, std::size_t(spp)); }

  private:
    // `cancel` (may be null) is polled between chunks, so an interrupt is seen within one chunk.
    // accum: the request's slots (SampleRequest), 3 floats each, zeroed by the caller.
    using TileFn = void (*)(const StreamRenderer&, const Tile&, const SampleRequest&, float* accum, RayCounts&,
                            StreamProfile*, const RenderProgress* cancel);
    template <bool kLighting, bool kShadows, bool kReflect, bool kRefract, bool kBounce, bool kJitter>
    static void render_tile(const StreamRenderer& self, const Tile& tile, const SampleRequest& req, float* accum,
                            RayCounts& counts, StreamProfile* profile, const RenderProgress* cancel);
    TileFn select_tile_fn() const;

    StreamScene scene_;
    const KernelTable& kernels_;
    TileFn tile_fn_;
    ShadeMode shade_mode_;  ///< resolved for this scene
    std::size_t slice_rays_;
    /// Whether a uniform tile hands its pixels over in Z order (render_one_tile): where rays
    /// walk one hierarchy, a mesh's tree without the object tree or the object tree of shapes.
    bool z_order_;
};

}  // namespace streamrt
