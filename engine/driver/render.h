#pragma once
// One entry point for both engines, used by the command line, the tests and perf/.
#include <cstddef>
#include <memory>
#include <string>

#include "image/framebuffer.h"
#include "kernels/kernel_table.h"
#include "stream/profile.h"
#include "stream/shade_mode.h"
#include "parallel/parallelism.h"
#include "render/render_stats.h"
#include "scene/scene.h"

namespace streamrt {

enum class EngineKind { Stream, Recursive };
const char* engine_name(EngineKind e);

struct RenderResult {
    Framebuffer image;
    RayCounts counts;
    double seconds = 0;        ///< rendering
    double setup_seconds = 0;  ///< building the engine's tables and the object hierarchy
};

struct EngineOptions {
    Isa isa = best_isa();               ///< stream engine: kernel level
    StreamProfile* profile = nullptr;   ///< stream engine: per-stage figures, when wanted
    ShadeMode shade = ShadeMode::Auto;  ///< stream engine: how the shade stage groups hits
    std::size_t slice_rays = 0;         ///< stream engine: most rays traced at once (0: default; tests)
};

/// An engine with its set-up done (tables, hierarchy), ready to render.
class PreparedRender {
  public:
    virtual ~PreparedRender() = default;
    virtual Framebuffer render(Parallelism& par, RenderProgress* progress) = 0;
    /// False when the engine rendering no longer reads the scene's objects (the stream engine
    /// renders from its own tables): the caller may then release them before rendering.
    virtual bool reads_scene_objects() const = 0;
    double setup_seconds = 0;
};

/// The set-up of an engine for `scene`, which must outlive it.
std::unique_ptr<PreparedRender> prepare_render(const Scene& scene, EngineKind engine, const EngineOptions& options = {});

/// Set-up then rendering, the two timed apart.
RenderResult render_prepared(PreparedRender& prepared, Parallelism& par, RenderProgress* progress = nullptr);

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par,
                          RenderProgress* progress = nullptr, const EngineOptions& options = {});

}  // namespace streamrt
