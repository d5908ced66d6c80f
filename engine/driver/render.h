#pragma once
// One entry point for both engines, used by the command line, the tests and perf/.
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "image/framebuffer.h"
#include "kernels/kernel_table.h"
#include "stream/profile.h"
#include "stream/shade_mode.h"
#include "parallel/parallelism.h"
#include "render/adaptive.h"
#include "render/render_stats.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "scene/scene_bvh.h"

namespace streamrt {

enum class EngineKind { Stream, Recursive };
inline constexpr EnumName<EngineKind> kEngineNames[] = {{EngineKind::Stream, "stream"}, {EngineKind::Recursive, "recursive"}};
const char* engine_name(EngineKind e);

struct RenderResult {
    Framebuffer image;
    /// Adaptive sampling only (render/adaptive.h): samples taken and the estimated error.
    std::optional<AdaptiveSummary> adaptive;
    /// Adaptive sampling only: per pixel, (samples taken, estimated standard error, 0).
    Framebuffer sample_map;
    RayCounts counts;
    double seconds = 0;        ///< rendering
    double setup_seconds = 0;  ///< building the engine's tables and the object hierarchy
};

/// When an adaptive render of the whole image stops refining, beside the pixels' own rule.
struct AdaptiveStop {
    double target_error = 0;  ///< > 0: once the estimated image RMSE is at most this
    double time_limit = 0;    ///< > 0: once this many seconds of rendering are spent
};

struct EngineOptions {
    Isa isa = best_isa();               ///< stream engine: kernel level
    StreamProfile* profile = nullptr;   ///< stream engine: per-stage figures, when wanted
    ShadeMode shade = ShadeMode::Auto;  ///< stream engine: how the shade stage groups hits
    std::size_t slice_rays = 0;         ///< stream engine: most rays traced at once (0: default; tests)
    accel::AccelConfig accel;           ///< both engines: whether and how the object hierarchy is used
    AdaptiveStop adaptive_stop;         ///< both engines: adaptive sampling's early stops (whole image)
    /// Adaptive sampling: fill RenderResult::sample_map. A front end that writes or returns
    /// no sample map says false, and the render skips a second image of the picture's size.
    bool sample_map = true;
};

/// An engine with its set-up done (tables, hierarchy), ready to render. Uniform or adaptive
/// sampling (render/adaptive.h, driver/adaptive_render.h) is chosen here from the scene's
/// settings; the engines trace what they are asked.
class PreparedRender {
  public:
    virtual ~PreparedRender() = default;
    /// The whole image. Adaptive: rounds across the image (stop may end them early), and
    /// last_adaptive / sample_map describe the outcome.
    Framebuffer render(Parallelism& par, RenderProgress* progress);
    /// True when the engine reads the scene's objects while rendering (the recursive engine:
    /// its hit points go through Md): it then holds the scene it renders (prepare_render's
    /// shared pointer) as long as it lives. False when it renders from its own tables (the
    /// stream engine: its meshes and images held through their own shared pointers): it holds
    /// nothing of the scene, and a caller that lets go of the scene frees its objects.
    virtual bool reads_scene_objects() const = 0;
    /// Renders one tile into `rgb` (tile.width() x tile.height() x 3 floats, row by row): the
    /// values render() gives those pixels, on any thread, in any process. Thread-safe.
    void render_tile(const Tile& tile, float* rgb, RayCounts& counts, const RenderProgress* cancel);
    /// Traces samples `run` of the listed pixels of `tile` (tile-local numbers, row by row),
    /// 3 floats per sample into `out`, pixel after pixel (adaptive sampling). Thread-safe.
    virtual void render_samples(const Tile& tile, SampleRun run, const std::uint32_t* pixels, int n_pixels, float* out,
                                RayCounts& counts, const RenderProgress* cancel) = 0;
    /// Animation (scene/animation.h): `scene` is the scene at another frame, a scene of the
    /// same objects at other places (scene_at_frame, never the prepared scene changed in
    /// place), and `change` what differs from the frame rendered so far (frame_change); the
    /// engine re-derives only that (moved objects' records and hierarchy boxes, refitted or
    /// rebuilt; lights; camera) and, if it reads the scene, holds `scene` in place of the one
    /// before. setup_seconds becomes the time this took.
    void update(std::shared_ptr<const Scene> scene, const FrameChange& change);
    /// The same for a scene the caller keeps alive as long as this (tests, perf/).
    void update(const Scene& scene, const FrameChange& change);
    /// After render_tile calls: completes the profile's description (stream engine).
    virtual void finish_tiles(double /*wall_seconds*/, int /*threads*/) {}
    double setup_seconds = 0;
    int width = 0, height = 0;  ///< the image's size (the scene's settings)
    AdaptiveRule adaptive;      ///< from the scene's settings (threshold 0: uniform)
    AdaptiveStop stop;          ///< whole-image adaptive renders only
    std::optional<AdaptiveSummary> last_adaptive;  ///< set by an adaptive render()
    bool keep_sample_map = true;                   ///< EngineOptions::sample_map
    Framebuffer sample_map;                        ///< set by an adaptive render() when keep_sample_map

  protected:
    virtual Framebuffer render_uniform(Parallelism& par, RenderProgress* progress) = 0;
    virtual void render_uniform_tile(const Tile& tile, float* rgb, RayCounts& counts, const RenderProgress* cancel) = 0;
    virtual void update_engine(std::shared_ptr<const Scene> scene, const FrameChange& change) = 0;
};

/// One finished tile: its number (tile_rect), rectangle, pixels, rays and render time.
struct TileOutput {
    int index = 0;
    Tile tile{};
    const float* rgb = nullptr;  ///< tile.width() x tile.height() x 3 floats, row by row
    RayCounts counts;
    double seconds = 0;
};
/// Receives finished tiles, from the worker threads (possibly several at once).
using TileSink = std::function<void(const TileOutput&)>;
/// Hands out tile numbers to render (thread-safe); a negative number: no more.
using TileSource = std::function<int()>;

/// The set-up of an engine for `scene` rendered with `settings` (a render job's, overrides
/// applied; the scene's own settings are not read). The prepared render holds `scene` while
/// it reads it (reads_scene_objects), so the caller's reference may be let go.
std::unique_ptr<PreparedRender> prepare_render(std::shared_ptr<const Scene> scene, const RenderSettings& settings,
                                               EngineKind engine, const EngineOptions& options = {});
/// The set-up of an engine for `scene` with its own settings; `scene` must outlive it (tests,
/// perf/).
std::unique_ptr<PreparedRender> prepare_render(const Scene& scene, EngineKind engine, const EngineOptions& options = {});

/// Set-up then rendering, the two timed apart.
RenderResult render_prepared(PreparedRender& prepared, Parallelism& par, RenderProgress* progress = nullptr);

/// Renders the tiles `source` hands out, on par's threads, each given to `sink` once done;
/// progress (optional) counts them and its cancel flag stops early. Whatever splits the
/// tiles (threads, processes, shards), a tile's pixels are the same.
void render_tiles(PreparedRender& prepared, Parallelism& par, const TileSource& source, const TileSink& sink,
                  RenderProgress* progress = nullptr);
/// The same for a list of tile numbers, taken in order.
void render_tiles(PreparedRender& prepared, Parallelism& par, std::span<const int> tiles, const TileSink& sink,
                  RenderProgress* progress = nullptr);

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par,
                          RenderProgress* progress = nullptr, const EngineOptions& options = {});

}  // namespace streamrt
