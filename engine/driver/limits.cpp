#include "driver/limits.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/memory_budget.h"
#include "image/image_io.h"
#include "kernels/stream_walk_memory.h"
#include "mesh/mesh.h"
#include "render/adaptive.h"
#include "stream/stream_renderer.h"

namespace streamrt {

namespace {
// Bytes per ray slot: RayStream 11 floats + pixel int32 + kind byte; ShadowStream 10 floats +
// pixel int32; per traced ray: closest-hit object int32 and mesh hit (int32 + 2 floats), sized
// as the slice's buffer (2 x slice); per ray shaded: its run key, its place in run order and
// its local colour (2 int32 + 3 floats; the shade stage reads the rays through that order).
constexpr double kRayBytes = 11 * 4 + 4 + 1;
constexpr double kShadowBytes = 10 * 4 + 4;
constexpr double kHitBytes = 4 + 12;
constexpr double kSortedBytes = 2 * 4 + 3 * 4;
constexpr double kRecursiveFrameBytes = 2048;  // one recursion level of the baseline, generous
}  // namespace

MemoryEstimate estimate_render_memory(const Scene& scene, const RenderSettings& s, bool stream_engine, int threads) {
    MemoryEstimate e;
    e.threads = std::max(1, threads);
    const double pixels = double(s.width) * double(s.height);
    e.framebuffer_bytes = pixels * 3 * sizeof(float);
    // Writing streams bands into the file: a few bands' buffers, never a copy of the image.
    e.output_bytes = image_write_buffer_bytes(s.width, s.height);
    bool spawns = false, bounces = false;
    for (const Material& m : scene.materials) {
        spawns = spawns || (s.degree >= 3 && m.refl > 0) || (s.degree >= 4 && m.trans > 0);
        bounces = bounces || (s.degree >= 6 && m.diff > 0);
    }
    spawns = spawns || bounces;
    // Children per ray: reflected and refracted, and at degree 6 a diffuse bounce.
    const double children = bounces ? 3.0 : 2.0;
    if (stream_engine) {
        const double slice = double(StreamRenderer::default_slice_rays(s.spp));
        e.slice_rays = slice;
        // Levels ws.pending (depth + 2 with spawns), plus the slice traced, its spawns and the
        // regrouping buffer: each at most `children` x slice rays.
        e.generations = spawns ? s.depth + 2 : 1;
        const double streams = (double(e.generations) + 3) * children * slice * kRayBytes;
        // Shadow rays per hit: one per light, `samples` per area light.
        double lights = 0.0;
        for (const Light& given : scene.lights) {
            const Light l = rendered_light(given, s);
            lights += s.degree >= 5 ? (l.is_area() ? double(l.samples) : 1.0) : 0.0;
        }
        // The shadow rays of a slice, twice (regrouped by pixel after gathered shading).
        e.per_thread_bytes = streams + 2 * slice * kHitBytes + slice * kSortedBytes + 2 * slice * lights * kShadowBytes;
        // A closest-hit stream (2 x slice rays at most) over meshes may be walked whole
        // (kernels/stream_walk_memory.h): its lists grow with the deepest mesh tree.
        int mesh_depth = 0;
        for (const auto& m : scene.meshes)
            if (m) mesh_depth = std::max(mesh_depth, m->bvh.stats.depth);
        if (mesh_depth > 0) e.per_thread_bytes += mesh_stream_walk_bytes(children * slice, mesh_depth);
    } else {
        e.per_thread_bytes = (double(s.depth) + 2) * kRecursiveFrameBytes;
    }
    if (s.adaptive > 0) {
        // Per pixel, at most (a pixel that stops at its corners has no tally): its tally, its
        // place in the tile and in the last round's list (two 32-bit indices), its neighbour
        // flag, its above-T flag (the neighbour rule's image, driver/adaptive_render.cpp) and
        // its sample-map pixel (counted whether or not a map is asked for: a bound).
        e.adaptive_bytes =
            pixels * (sizeof(PixelTally) + 2 * sizeof(std::uint32_t) + 2 * sizeof(std::uint8_t) + 3 * sizeof(float));
        // The first round's corners, (width + 1) x (height + 1) colours (render/adaptive.h).
        if (AdaptiveRule{s.adaptive, s.spp}.corner_round())
            e.adaptive_bytes += (double(s.width) + 1) * (double(s.height) + 1) * 3 * sizeof(float);
        // A tile's round is traced whole: its pixels' samples' colours, at most half the cap each.
        const double largest_round = double(std::max(adaptive_round(0, s.spp).count, s.spp / 2));
        e.per_thread_bytes += double(kTileSize) * kTileSize * largest_round * 3 * sizeof(float);
    }
    e.total_bytes = e.framebuffer_bytes + e.output_bytes + e.adaptive_bytes + double(e.threads) * e.per_thread_bytes;
    return e;
}

double physical_memory_bytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return 0;
    return double(pages) * double(page);
}

void check_render_memory(const Scene& scene, const RenderSettings& s, bool stream_engine, int threads,
                         double limit_bytes) {
    if (limit_bytes == 0) return;
    const MemoryBudget budget = limit_bytes < 0 ? MemoryBudget::now() : MemoryBudget::of(limit_bytes);
    const MemoryEstimate e = estimate_render_memory(scene, s, stream_engine, threads);
    if (e.total_bytes <= budget.left()) return;
    std::string msg = "image " + std::to_string(s.width) + "x" + std::to_string(s.height) + ", spp " +
                      std::to_string(s.spp) + ", depth " + std::to_string(s.depth) + " would need about " +
                      format_bytes(e.total_bytes) + " of memory (framebuffer " + format_bytes(e.framebuffer_bytes) +
                      (e.adaptive_bytes > 0 ? ", adaptive tallies " + format_bytes(e.adaptive_bytes) : std::string()) +
                      ", output " + format_bytes(e.output_bytes) + ", " + std::to_string(e.threads) + " thread" +
                      (e.threads > 1 ? "s" : "") + " x " + format_bytes(e.per_thread_bytes) +
                      (stream_engine ? " of ray streams" : " of stack");
    msg += ") but " + budget.describe() + "; lower --width/--height, --spp, --depth or -j" +
           (MemoryBudget::limit() > 0 ? ", or raise --memory-limit" : "");
    throw MemoryShortage(msg);
}

}  // namespace streamrt
