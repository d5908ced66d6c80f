// Timing program for reading OBJ meshes (docs/performance.md, "## Reading OBJ meshes"). Not a test.
//
//   obj_bench [FILE] [-r RUNS] [-j J]...
//
// Reads FILE (default /tmp/streamrt_obj_bench.obj; written here when absent: a UV sphere of
// 1 000 000 triangles, coordinates with 6 decimals as most exporters write them, 38 MB) RUNS
// times (default 5) at each -j (default 1 and 2) with
//   tinyobjloader  as the engine read OBJ files before obj_reader: the file into a string,
//                  ObjReader::ParseFromString, the triangles' vertex numbers gathered (one thread);
//   parse_obj      the file mapped and parsed (what load_obj_mesh reads with);
//   load_obj_mesh  all of it: parse_obj and the mesh built (normals, hierarchy), for scale;
//     before       the same with tinyobjloader reading (the engine's load_obj_mesh before).
// Prints the median wall time, the MB/s it gives and the median CPU time (user + system, all
// threads), and whether both readers agree.
#include <sys/resource.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/mapped_file.h"
#include "mesh/mesh.h"
#include "mesh/obj_reader.h"
#include "parallel/parallelism.h"
#include "reader_bench_args.h"

using namespace streamrt;

namespace {

/// A UV sphere of 2 * segments * (rings - 1) triangles, written with %.6f coordinates.
bool write_sphere(const std::string& path, int rings, int segments) {
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    std::fprintf(f, "# UV sphere, %d rings, %d segments (streamrt perf/obj_bench)\nv 0 1 0\n", rings, segments);
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const double th = std::numbers::pi * i / rings, ph = 2 * std::numbers::pi * j / segments;
            std::fprintf(f, "v %.6f %.6f %.6f\n", std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        }
    std::fprintf(f, "v 0 -1 0\n");
    const int south = 2 + (rings - 1) * segments;
    const auto ring = [&](int i, int j) { return 2 + (i - 1) * segments + j % segments; };
    for (int j = 0; j < segments; ++j) {
        std::fprintf(f, "f 1 %d %d\n", ring(1, j + 1), ring(1, j));
        std::fprintf(f, "f %d %d %d\n", south, ring(rings - 1, j), ring(rings - 1, j + 1));
    }
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            std::fprintf(f, "f %d %d %d\n", ring(i, j), ring(i, j + 1), ring(i + 1, j + 1));
            std::fprintf(f, "f %d %d %d\n", ring(i, j), ring(i + 1, j + 1), ring(i + 1, j));
        }
    return std::fclose(f) == 0;
}

/// The engine's OBJ reading before obj_reader (mesh.cpp's read_file_bytes and read_obj_faces).
void tinyobj_read(const std::string& path, std::vector<float>& positions, std::vector<std::uint32_t>& tris) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromString(ss.str(), "", config)) {
        std::fprintf(stderr, "obj_bench: tinyobjloader: %s\n", reader.Error().c_str());
        std::exit(1);
    }
    positions = reader.GetAttrib().vertices;
    tris.clear();
    for (const tinyobj::shape_t& s : reader.GetShapes())
        for (const tinyobj::index_t& ix : s.mesh.indices) tris.push_back(std::uint32_t(ix.vertex_index));
}

/// The process's CPU time (user + system, all threads), seconds.
double cpu_seconds() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    const auto secs = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
    return secs(ru.ru_utime) + secs(ru.ru_stime);
}

/// Wall and CPU seconds of f() (the machine is shared: wall time alone says little when other
/// builds hold the cores).
struct Timing {
    std::vector<double> wall, cpu;
    template <class F>
    void add(F&& f) {
        const double c0 = cpu_seconds();
        const auto t0 = std::chrono::steady_clock::now();
        f();
        wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        cpu.push_back(cpu_seconds() - c0);
    }
};

void print(const char* what, int j, const Timing& t, double mb) {
    const double w = median(t.wall);
    std::printf("%-14s %-4s %7.3f s %6.0f MB/s  cpu %.3f s  (runs %.3f .. %.3f s)\n", what,
                j ? ("-j" + std::to_string(j)).c_str() : "", w, mb / w, median(t.cpu),
                *std::min_element(t.wall.begin(), t.wall.end()), *std::max_element(t.wall.begin(), t.wall.end()));
}

}  // namespace

int main(int argc, char** argv) {
    const ReaderBenchArgs args = parse_reader_bench_args(argc, argv, "/tmp/streamrt_obj_bench.obj");
    const std::string& path = args.path;
    const int runs = args.runs;
    const std::vector<int>& jobs = args.jobs;
    if (!std::filesystem::exists(path)) {
        std::printf("writing %s\n", path.c_str());
        if (!write_sphere(path, 501, 1000)) {
            std::fprintf(stderr, "obj_bench: cannot write %s\n", path.c_str());
            return 1;
        }
    }
    const double mb = double(std::filesystem::file_size(path)) / 1e6;
    std::printf("%s: %.1f MB, %d runs each, medians\n", path.c_str(), mb, runs);

    // Agreement: the same triangles; positions equal but where tinyobjloader's own number
    // conversion (not correctly rounded) is an ulp off.
    std::vector<float> tiny_pos;
    std::vector<std::uint32_t> tiny_tris;
    tinyobj_read(path, tiny_pos, tiny_tris);
    {
        MappedFile file;
        if (!file.open(path)) return 1;
        const ObjData d = parse_obj(file.text(), path);
        std::size_t differ = 0, beyond_ulp = 0;
        for (std::size_t k = 0; k < std::min(d.positions.size(), tiny_pos.size()); ++k)
            if (d.positions[k] != tiny_pos[k]) {
                ++differ;
                if (std::nextafter(d.positions[k], tiny_pos[k]) != tiny_pos[k]) ++beyond_ulp;
            }
        std::printf("%zu triangles, %zu vertices; triangles %s tinyobjloader's; %zu of %zu coordinates differ by an ulp, "
                    "%zu by more\n",
                    d.triangles.size() / 3, d.positions.size() / 3, d.triangles == tiny_tris ? "equal to" : "DIFFER from",
                    differ, d.positions.size(), beyond_ulp + (d.positions.size() != tiny_pos.size() ? 1 : 0));
    }

    Timing tiny;
    for (int r = 0; r < runs; ++r) tiny.add([&] { tinyobj_read(path, tiny_pos, tiny_tris); });
    print("tinyobjloader", 0, tiny, mb);
    for (const int j : jobs) {
        Parallelism par(j);
        Timing parse, load, old_load;
        for (int r = 0; r < runs; ++r)
            old_load.add([&] {
                par.run([&] {
                    tinyobj_read(path, tiny_pos, tiny_tris);
                    Mesh::build(path, tiny_pos, tiny_tris);
                });
            });
        for (int r = 0; r < runs; ++r)
            parse.add([&] {
                par.run([&] {
                    MappedFile file;
                    if (!file.open(path) || parse_obj(file.text(), path).triangles.size() != tiny_tris.size()) std::exit(1);
                });
            });
        for (int r = 0; r < runs; ++r)
            load.add([&] { par.run([&] { load_obj_mesh(path); }); });
        print("parse_obj", j, parse, mb);
        print("load_obj_mesh", j, load, mb);
        print("  before", j, old_load, mb);
    }
    return 0;
}
