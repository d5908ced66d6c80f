#include "driver/limits.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "image/image_io.h"

namespace streamrt {

namespace {
constexpr double kChunkRays = 4096;  // StreamRenderer::kMaxChunkRays
// Bytes per ray slot: RayStream 10 floats + pixel int32 + kind byte; closest-hit object
// int32; ShadowStream 10 floats + pixel int32.
constexpr double kRayBytes = 10 * 4 + 4 + 1;
constexpr double kObjectBytes = 4;
constexpr double kShadowBytes = 10 * 4 + 4;
constexpr double kRecursiveFrameBytes = 2048;  // one recursion level of the baseline, generous
}  // namespace

MemoryEstimate estimate_render_memory(const Scene& scene, bool stream_engine, int threads) {
    const RenderSettings& s = scene.settings;
    MemoryEstimate e;
    e.threads = std::max(1, threads);
    const double pixels = double(s.width) * double(s.height);
    e.framebuffer_bytes = pixels * 3 * sizeof(float);
    // Writing streams bands into the file: a few bands' buffers, never a copy of the image.
    e.output_bytes = image_write_buffer_bytes(s.width, s.height);
    bool reflect = false, both = false;
    for (const Material& m : scene.materials) {
        const bool r = s.degree >= 3 && m.refl > 0;
        const bool t = s.degree >= 4 && m.trans > 0;
        reflect = reflect || r || t;
        both = both || (r && t);
    }
    e.branching = both ? 2 : 1;
    if (stream_engine) {
        const double primary = std::max(kChunkRays, double(s.spp));
        const double depth = reflect ? double(s.depth) : 0.0;
        const double peak = primary * std::pow(double(e.branching), depth);
        e.peak_stream_rays = peak;
        const double lights = s.degree >= 5 ? double(scene.lights.size()) : 0.0;
        // current generation, the next one (reserved at twice the current), hit objects,
        // shadow rays (one per light and ray).
        e.per_thread_bytes = peak * kRayBytes + 2 * peak * kRayBytes + peak * kObjectBytes + peak * lights * kShadowBytes;
    } else {
        e.per_thread_bytes = (double(s.depth) + 2) * kRecursiveFrameBytes;
    }
    e.total_bytes = e.framebuffer_bytes + e.output_bytes + double(e.threads) * e.per_thread_bytes;
    return e;
}

double physical_memory_bytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return 0;
    return double(pages) * double(page);
}

std::string format_bytes(double bytes) {
    const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    int u = 0;
    while (u < 4 && bytes >= 1024) {
        bytes /= 1024;
        ++u;
    }
    char buf[64];
    if (bytes >= 1e6) std::snprintf(buf, sizeof buf, "%.3g %s", bytes, units[u]);
    else if (u == 0) std::snprintf(buf, sizeof buf, "%.0f %s", bytes, units[u]);
    else std::snprintf(buf, sizeof buf, "%.1f %s", bytes, units[u]);
    return buf;
}

void check_render_memory(const Scene& scene, bool stream_engine, int threads, double limit_bytes) {
    if (limit_bytes < 0) limit_bytes = physical_memory_bytes();
    if (!(limit_bytes > 0)) return;
    const MemoryEstimate e = estimate_render_memory(scene, stream_engine, threads);
    if (e.total_bytes <= limit_bytes) return;
    const RenderSettings& s = scene.settings;
    std::string msg = "image " + std::to_string(s.width) + "x" + std::to_string(s.height) + ", spp " +
                      std::to_string(s.spp) + ", depth " + std::to_string(s.depth) + " would need about " +
                      format_bytes(e.total_bytes) + " of memory (framebuffer " + format_bytes(e.framebuffer_bytes) +
                      ", output " + format_bytes(e.output_bytes) + ", " + std::to_string(e.threads) + " thread" +
                      (e.threads > 1 ? "s" : "") + " x " + format_bytes(e.per_thread_bytes) +
                      (stream_engine ? " of ray streams" : " of stack");
    if (stream_engine && e.branching > 1)
        msg += ", up to 2^" + std::to_string(s.depth) + " secondary rays per primary ray";
    msg += ") but this machine has " + format_bytes(limit_bytes) +
           "; lower --width/--height, --spp, --depth or -j";
    throw UsageError(msg);
}

}  // namespace streamrt
