// What a mesh takes in memory, built by streamrt and by Embree 3 (docs/performance.md, "Memory
// per vertex and triangle"). Not a test; built with embree_rays (perf/CMakeLists.txt).
//
//   mesh_memory streamrt MESH.{obj,ply}[.gz]
//   mesh_memory embree [--quality medium|high] MESH.{obj,ply}[.gz]
//
// Both read the file's positions and triangles with streamrt's readers (parse_obj, parse_ply),
// then build: streamrt's Mesh (taking the positions over), or an Embree scene of the same
// triangles (RTC_GEOMETRY_TYPE_TRIANGLE in buffers Embree allocates, as a renderer hands it a
// mesh; a device with threads=1; quality high by default, embree_rays' setting), after which
// the read arrays are freed. One engine per process, so that each process's peak is its own.
// Printed, per triangle:
//   held      what the built mesh holds by the library's own count: Mesh::memory_bytes, or
//             the bytes Embree's memory monitor (rtcSetDeviceMemoryMonitorFunction) saw
//             allocated and not freed once the scene is committed
//   build     the most the monitor saw at once during the build (Embree only)
//   resident  the process's resident memory growth from before the read to after the build,
//             the read arrays freed and the allocator's free pages given back (malloc_trim)
//   peak      the process's peak resident memory (VmHWM) less its resident memory at start
#include <embree3/rtcore.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

#include "core/memory_budget.h"
#include "mesh/mesh.h"
#include "mesh/mesh_bytes.h"
#include "mesh/obj_reader.h"
#include "mesh/ply_reader.h"

using namespace streamrt;

namespace {

double status_kib(const char* field) {
    std::ifstream in("/proc/self/status");
    for (std::string line; std::getline(in, line);)
        if (line.rfind(field, 0) == 0) return std::stod(line.substr(std::strlen(field)));
    return 0.0;
}

std::atomic<long long> embree_bytes{0};
long long embree_peak = 0;

bool monitor(void*, ssize_t bytes, bool) {
    const long long now = embree_bytes += bytes;
    embree_peak = std::max(embree_peak, now);  // the device has one thread
    return true;
}

struct Triangles {
    std::vector<float> positions;
    std::vector<std::uint32_t> triangles;
};

Triangles read_triangles(const std::string& path) {
    MemoryBudget budget = MemoryBudget::now();
    MeshBytes bytes(path, budget);
    if (is_ply_path(path)) {
        PlyData d = parse_ply(bytes.text(), path);
        return {std::move(d.positions), std::move(d.triangles)};
    }
    ObjData d = parse_obj(bytes.text(), path);
    return {std::move(d.positions), std::move(d.triangles)};
}

}  // namespace

int main(int argc, char** argv) {
    std::string engine, file;
    RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--quality" && i + 1 < argc) {
            const std::string q = argv[++i];
            if (q != "medium" && q != "high") return std::fprintf(stderr, "--quality: medium or high\n"), 2;
            quality = q == "high" ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
        } else if (engine.empty()) {
            engine = a;
        } else {
            file = a;
        }
    }
    if ((engine != "streamrt" && engine != "embree") || file.empty())
        return std::fprintf(stderr, "usage: mesh_memory streamrt|embree [--quality medium|high] MESH\n"), 2;

    const double start_kib = status_kib("VmRSS:");
    std::size_t triangles = 0, vertices = 0;
    double held = 0.0, build = 0.0;
    std::shared_ptr<const Mesh> mesh;
    RTCDevice dev = nullptr;
    RTCScene scene = nullptr;
    try {
        Triangles t = read_triangles(file);
        vertices = t.positions.size() / 3;
        if (engine == "streamrt") {
            mesh = Mesh::build(file, std::move(t.positions), std::move(t.triangles));
            triangles = mesh->triangle_count();
            held = double(mesh->memory_bytes());
        } else {
            dev = rtcNewDevice("threads=1");
            if (!dev) return std::fprintf(stderr, "rtcNewDevice failed\n"), 1;
            rtcSetDeviceMemoryMonitorFunction(dev, monitor, nullptr);
            triangles = t.triangles.size() / 3;
            scene = rtcNewScene(dev);
            rtcSetSceneBuildQuality(scene, quality);
            RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetGeometryBuildQuality(g, quality);
            // The vertex buffer's last element is read with 16-byte loads: Embree asks for 4
            // bytes of padding past it, given here by one more vertex.
            auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                   3 * sizeof(float), vertices + 1));
            auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                      3 * sizeof(unsigned), triangles));
            std::copy(t.positions.begin(), t.positions.end(), vb);
            std::copy(t.triangles.begin(), t.triangles.end(), ib);
            t = {};  // Embree holds the copies: the read arrays go before the build
            rtcCommitGeometry(g);
            rtcAttachGeometry(scene, g);
            rtcReleaseGeometry(g);
            embree_peak = embree_bytes;
            rtcCommitScene(scene);
            held = double(embree_bytes);
            build = double(embree_peak);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    ::malloc_trim(0);
    const double resident = (status_kib("VmRSS:") - start_kib) * 1024.0;
    const double peak = (status_kib("VmHWM:") - start_kib) * 1024.0;
    const double n = double(triangles);
    char build_text[32] = "-";  // Embree's monitor only
    if (build > 0) std::snprintf(build_text, sizeof build_text, "%.1f", build / n);
    std::printf("%s%s: %zu triangles, %zu vertices; bytes a triangle: held %.1f, build %s, resident %.1f, peak %.1f\n",
                engine.c_str(), engine == "embree" ? (quality == RTC_BUILD_QUALITY_HIGH ? " (high)" : " (medium)") : "",
                triangles, vertices, held / n, build_text, resident / n, peak / n);
    if (scene) rtcReleaseScene(scene);
    if (dev) rtcReleaseDevice(dev);
    return 0;
}
