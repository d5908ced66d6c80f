#pragma once
// Limits checked before anything big is allocated: a render whose worst-case memory exceeds
// the memory budget (core/memory_budget.h) is refused with a message saying what it would need.
#include <cstdint>
#include <string>

#include "core/memory_budget.h"  // format_bytes, MemoryShortage
#include "scene/scene.h"

namespace streamrt {

/// Worst-case bytes a render needs, by part (doubles: the worst case can exceed 2^64).
struct MemoryEstimate {
    double framebuffer_bytes = 0;  ///< width*height*3 floats
    double output_bytes = 0;       ///< the image writer's band buffers (image_write_buffer_bytes)
    double per_thread_bytes = 0;   ///< ray streams of one worker (stream engine) or its stack
    /// Adaptive sampling (render/adaptive.h): a tally, a neighbour flag and a sample-map pixel
    /// per pixel; per thread, the colours of one tile's largest round (in per_thread_bytes).
    double adaptive_bytes = 0;
    int threads = 1;
    double total_bytes = 0;        ///< framebuffer + output + adaptive + threads * per_thread
    double slice_rays = 0;         ///< stream engine: most rays of a generation traced at once
    int generations = 0;           ///< stream engine: generations whose rays may be held at once
};

/// The stream engine traces at most slice = max(16384, spp) rays of a generation at once and
/// the generations deepest first (stream/stages.h, trace_generation): per thread it holds at
/// most 2 x slice rays per generation a ray can reach (depth + 2 with mirrors or glass, else 1),
/// plus a few slice-sized buffers; linear in depth, never 2^depth.
/// `settings`: what is rendered (a render job's); the scene's own in the second form.
MemoryEstimate estimate_render_memory(const Scene& scene, const RenderSettings& settings, bool stream_engine,
                                      int threads);
inline MemoryEstimate estimate_render_memory(const Scene& scene, bool stream_engine, int threads) {
    return estimate_render_memory(scene, scene.settings, stream_engine, threads);
}

/// Physical memory of the machine: sysconf(_SC_PHYS_PAGES) * page size (0 if unknown).
double physical_memory_bytes();

/// Throws MemoryShortage (one line, what it would need and what there is) when the estimate
/// exceeds `limit_bytes` (default, -1: the memory budget now, core/memory_budget.h; 0: no check).
void check_render_memory(const Scene& scene, const RenderSettings& settings, bool stream_engine, int threads,
                         double limit_bytes = -1);
inline void check_render_memory(const Scene& scene, bool stream_engine, int threads, double limit_bytes = -1) {
    check_render_memory(scene, scene.settings, stream_engine, threads, limit_bytes);
}


}  // namespace streamrt
