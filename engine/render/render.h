#pragma once
// One entry point for both engines, used by the command line, the tests and perf/.
#include <string>

#include "image/framebuffer.h"
#include "kernels/kernel_table.h"
#include "stream/profile.h"
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
    bool scalar_shade = false;          ///< stream engine: scalar shade stage (for measurement)
};

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par,
                          RenderProgress* progress = nullptr, const EngineOptions& options = {});

}  // namespace streamrt
