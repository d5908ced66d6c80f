#pragma once
// One entry point for both engines, used by the command line, the tests and perf/.
#include <string>

#include "image/framebuffer.h"
#include "parallel/parallelism.h"
#include "render/render_stats.h"
#include "scene/scene.h"

namespace streamrt {

enum class EngineKind { Stream, Recursive };
const char* engine_name(EngineKind e);

struct RenderResult {
    Framebuffer image;
    RayCounts counts;
    double seconds = 0;
};

RenderResult render_scene(const Scene& scene, EngineKind engine, Parallelism& par,
                          RenderProgress* progress = nullptr);

}  // namespace streamrt
