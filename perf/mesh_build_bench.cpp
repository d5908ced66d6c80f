// Timing program for building a mesh from a file's triangles (docs/performance.md, "Building
// a mesh's hierarchy"). Not a test.
//
//   mesh_build_bench FILE [-j J] [--runs N]
//
// Reads FILE (PLY or OBJ) once, then builds the mesh from its vertices and triangles N times
// (default 8) on J threads (default 2): triangle boxes, the binned SAH hierarchy and its
// collapse to 8-wide nodes, the leaf-order copies and the triangle blocks. Prints the first
// build's time (on memory fresh from the system, as in a render: its pages are zeroed on first
// touch), the median of the later ones and of their hierarchy alone (Bvh::stats.seconds;
// the allocator reuses the pages freed by the build before), and the tree it made
// (nodes, leaves, and its SAH cost: the same tree gives the same cost, so a faster builder
// can be checked for the trees it makes as well as for its time).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/mapped_file.h"
#include "mesh/mesh.h"
#include "mesh/obj_reader.h"
#include "mesh/ply_reader.h"
#include "parallel/parallelism.h"
#include "bench_clock.h"

using namespace streamrt;
using streamrt::perf::now;

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// SAH cost of the wide tree, relative to its root box's area: each node's children tested
/// once per visit (1 per node) and each leaf's triangles (1 per triangle), weighted by the
/// area of the box that leads there.
double sah_cost(const accel::Bvh& bvh) {
    double cost = 0.0;
    const auto area = [](const float lo[3], const float hi[3]) {
        const double dx = double(hi[0]) - lo[0], dy = double(hi[1]) - lo[1], dz = double(hi[2]) - lo[2];
        return dx * dy + dy * dz + dz * dx;
    };
    const double root = area(bvh.bounds.lo, bvh.bounds.hi);
    for (const accel::WideNode& n : bvh.nodes)
        for (int j = 0; j < accel::kNodeWidth; ++j) {
            if (n.child[j] < 0) continue;  // empty slot
            const float lo[3] = {n.lo_x[j], n.lo_y[j], n.lo_z[j]}, hi[3] = {n.hi_x[j], n.hi_y[j], n.hi_z[j]};
            const double w = area(lo, hi) / root;
            cost += n.count[j] > 0 ? w * double(n.count[j]) : w;  // a leaf's triangles, or a node's visit
        }
    return cost + 1.0;  // the root node itself
}

}  // namespace

int main(int argc, char** argv) {
    std::string path;
    int jobs = 2, runs = 8;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-j" && i + 1 < argc) jobs = std::atoi(argv[++i]);
        else if (a == "--runs" && i + 1 < argc) runs = std::atoi(argv[++i]);
        else path = a;
    }
    if (path.empty() || jobs < 1 || runs < 1) {
        std::fprintf(stderr, "usage: mesh_build_bench FILE.ply|FILE.obj [-j J] [--runs N]\n");
        return 2;
    }
    std::vector<float> positions, normals;
    std::vector<std::uint32_t> triangles;
    {
        MappedFile file;
        if (!file.open(path)) {
            std::fprintf(stderr, "mesh_build_bench: cannot open %s\n", path.c_str());
            return 1;
        }
        try {
            if (is_ply_path(path)) {
                PlyData d = parse_ply(file.text(), path);
                positions = std::move(d.positions), normals = std::move(d.normals), triangles = std::move(d.triangles);
            } else {
                ObjData d = parse_obj(file.text(), path);
                positions = std::move(d.positions), triangles = std::move(d.triangles);
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 1;
        }
    }
    Parallelism par(jobs);
    std::vector<double> whole, tree;
    std::shared_ptr<const Mesh> mesh;
    for (int r = 0; r < runs; ++r) {
        mesh.reset();
        const double t0 = now();
        mesh = Mesh::build(path, positions, triangles, {}, {}, normals);
        whole.push_back(now() - t0);
        tree.push_back(mesh->bvh.stats.seconds);
    }
    const accel::Bvh& b = mesh->bvh;
    const double first = whole.front(), first_tree = tree.front();
    if (runs > 1) {
        whole.erase(whole.begin());
        tree.erase(tree.begin());
    }
    std::printf("%s: %zu triangles, -j%d: first build %.4f s (hierarchy %.4f s); median of %zu later: %.4f s "
                "(hierarchy %.4f s), %.2f M triangles/s; %zu binary nodes, %zu wide nodes, %zu leaves, SAH cost %.3f\n",
                path.c_str(), mesh->triangle_count(), jobs, first, first_tree, whole.size(), median(whole),
                median(tree), double(mesh->triangle_count()) / median(whole) * 1e-6, b.stats.binary_nodes,
                b.stats.wide_nodes, b.stats.leaves, sah_cost(b));
    return 0;
}
