// Timing program: whole-stream traversal (perf/stream_walk.h) against the engine's mesh
// kernel (the packet walk, with its single-ray hand-over), one thread, the ray sets of
// perf/mesh_rays.h (docs/performance.md, "Whole streams through the tree"). Not a test.
//
//   stream_walk_bench [--reps N] [--rays primary,shadow,mirror,glass,diffuse] [--shuffle] [--chunk N] MESH.{obj,ply} ...
//
// --chunk N walks each stream as consecutive pieces of N rays, one walk each (a renderer's
// streams are a tile's rays of one generation, not the whole picture's). --inside K adds K
// generations of rays reflected inside the mesh, from the glass rays on (what a glass mesh's
// deep rays do between its faces; "inside 1" are the glass rays' reflections at the faces they
// reach); `--rays none` leaves out the five usual sets.
// For each mesh and ray kind: Mrays/s of the engine's kernel (AVX-512) as the packet walk and
// as the single-ray walk from the root, and of the stream walk (medians of N runs), the stream
// walk over the faster of the two, its rays per node visit (how many rays share the node's
// load; they are tested 16 at a time), and a check that it found the packet walk's hits.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh/ply_reader.h"
#include "mesh_rays.h"
#include "stream_walk.h"

using namespace streamrt;
using namespace streamrt::perf;

namespace {

struct WalkResult {
    double mrays = 0;
    StreamWalkStats stats;
    std::size_t hits = 0, differ = 0;
};

/// The stream walk over `st`, median of reps runs, and its hits compared with the engine
/// kernel's (t and triangle for closest hits, blocked or not for any hits).
WalkResult time_stream_walk(const Mesh& mesh, const Stream& st, bool any, const KernelTable& kt, const ObjectXf& xf,
                            int reps, std::size_t chunk) {
    const std::size_t n = st.count;
    std::vector<float> t(n), u(n), v(n);
    std::vector<std::int32_t> prim(n);
    std::vector<std::uint8_t> blocked(n);
    WalkResult out;
    const double sec = median_seconds(reps, [&] {
        std::copy_n(st.t_max.begin(), n, t.begin());
        std::fill(prim.begin(), prim.end(), -1);
        std::fill(blocked.begin(), blocked.end(), 0);
        const double t0 = now();
        out.stats = {};
        for (std::size_t k = 0; k < n; k += chunk) {
            const StreamRays rays{st.ox.data() + k, st.oy.data() + k, st.oz.data() + k, st.dx.data() + k,
                                  st.dy.data() + k, st.dz.data() + k, std::min(chunk, n - k), t.data() + k,
                                  prim.data() + k, u.data() + k, v.data() + k, blocked.data() + k};
            const StreamWalkStats piece = stream_walk(mesh.view(), rays, any);
            out.stats.nodes += piece.nodes, out.stats.node_rays += piece.node_rays, out.stats.leaf_rays += piece.leaf_rays;
        }
        return now() - t0;
    });
    out.mrays = double(n) / sec * 1e-6;
    // The engine's answer, once.
    simd::AlignedVec<float> et(st.t_max.size()), eu(et.size()), ev(et.size());
    simd::AlignedVec<std::int32_t> id(et.size(), -1), eprim(et.size(), -1);
    std::copy(st.t_max.begin(), st.t_max.end(), et.begin());
    RayView view = st.view(et.data());
    if (any) {
        kt.any[int(ShapeKind::Mesh)](view, &xf, 1);
    } else {
        view.prim = eprim.data(), view.bu = eu.data(), view.bv = ev.data();
        kt.closest[int(ShapeKind::Mesh)](view, id.data(), &xf, 1);
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (any) {
            const bool engine_blocked = st.t_max[i] > 0 && et[i] == 0;
            out.hits += blocked[i];
            out.differ += engine_blocked != bool(blocked[i]);
        } else {
            const bool engine_hit = id[i] == 0;
            out.hits += prim[i] >= 0;
            out.differ += engine_hit != (prim[i] >= 0) || (engine_hit && (eprim[i] != prim[i] || et[i] != t[i]));
        }
    }
    return out;
}

/// The rays of `in` that hit the mesh, reflected at their hits back into it (the face's normal
/// turned to meet the ray, the origin 1e-4 off the face on the ray's side), in the same order.
Stream reflect_inside(const Mesh& mesh, const Stream& in, const KernelTable& kt, const ObjectXf& xf) {
    simd::AlignedVec<float> t(in.t_max), bu(t.size()), bv(t.size());
    simd::AlignedVec<std::int32_t> id(t.size(), -1), prim(t.size(), -1);
    RayView v = in.view(t.data());
    v.prim = prim.data(), v.bu = bu.data(), v.bv = bv.data();
    kt.closest[int(ShapeKind::Mesh)](v, id.data(), &xf, 1);
    Stream out;
    for (std::size_t i = 0; i < in.count; ++i) {
        if (id[i] != 0) continue;
        const Vec3f o{in.ox[i], in.oy[i], in.oz[i]}, d{in.dx[i], in.dy[i], in.dz[i]};
        const std::array<float, 9> hit = mesh.triangle(std::size_t(prim[i]));
        const float* q = hit.data();
        Vec3f n = normalize(cross(Vec3f{q[3] - q[0], q[4] - q[1], q[5] - q[2]}, Vec3f{q[6] - q[0], q[7] - q[1], q[8] - q[2]}));
        if (dot(n, d) > 0) n = -n;
        out.add(o + t[i] * d + 1e-4f * n, d - 2.f * dot(d, n) * n, 1e30f);
    }
    out.pad();
    return out;
}

}  // namespace

// Here, in the file built for any x86-64, not in the AVX-512 one: it runs before anything knows
// the CPU has those instructions.
bool streamrt::perf::stream_walk_supported() {
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw");
}

int main(int argc, char** argv) {
    int reps = 5;
    bool shuffle = false;
    std::size_t chunk = 0;
    int inside = 0;
    std::string only;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--reps" && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
        else if (a == "--rays" && i + 1 < argc) only = argv[++i];
        else if (a == "--shuffle") shuffle = true;
        else if (a == "--inside" && i + 1 < argc) inside = std::max(0, std::atoi(argv[++i]));
        else if (a == "--chunk" && i + 1 < argc) chunk = std::size_t(std::max(16, std::atoi(argv[++i])));
        else if (!a.empty() && a[0] == '-') {
            std::fprintf(stderr, "usage: stream_walk_bench [--reps N] [--rays primary,shadow,mirror,glass,diffuse] "
                                 "[--shuffle] [--chunk N] [--inside K] MESH.{obj,ply} ...\n");
            return 2;
        } else files.push_back(a);
    }
    if (files.empty()) return std::fprintf(stderr, "usage: stream_walk_bench [--reps N] [--rays KIND,...] [--shuffle] MESH ...\n"), 2;
    if (!stream_walk_supported()) {
        std::printf("stream_walk_bench: this CPU has no AVX-512; nothing measured\n");
        return 0;
    }
    const KernelTable& kt = kernel_table(Isa::Avx512);
    std::printf("whole-stream walk against the engine's mesh kernel (avx512: packet walk, single-ray walk); "
                "one thread, median of %d, Mrays/s\n", reps);
    for (const std::string& file : files) {
        std::shared_ptr<const Mesh> mesh;
        try {
            mesh = load_mesh_file(file, false);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 1;
        }
        ObjectXf xf{};
        xf.m[0] = xf.m[5] = xf.m[10] = 1.f;
        xf.mesh = &mesh->view();
        Streams s = make_streams(*mesh, kt, xf, view_of_bounds(mesh->lo, mesh->hi));
        std::vector<Stream> deep;  // reflected inside from the glass rays, generation by generation
        for (int g = 0; g < inside; ++g) deep.push_back(reflect_inside(*mesh, g == 0 ? s.glass : deep.back(), kt, xf));
        if (shuffle) {
            for (Stream* st : {&s.primary, &s.shadow, &s.mirror, &s.glass, &s.diffuse}) st->shuffle();
            for (Stream& st : deep) st.shuffle();
        }
        std::vector<RaySet> sets = ray_sets(s, only);
        std::vector<std::string> deep_names;
        for (int g = 0; g < inside; ++g) deep_names.push_back("inside " + std::to_string(g + 1));
        for (int g = 0; g < inside; ++g) sets.push_back({deep_names[std::size_t(g)].c_str(), &deep[std::size_t(g)], false});
        std::printf("\n%s: %zu triangles%s", file.c_str(), mesh->triangle_count(), shuffle ? ", rays in a random order" : "");
        if (chunk) std::printf(", walked %zu rays at a time", chunk);
        std::printf("\n");
        std::printf("%-8s %9s %10s %10s %10s %7s %12s %14s\n", "rays", "count", "packet", "single", "stream", "ratio",
                    "rays/node", "hits (differ)");
        const SingleRayMesh single(*mesh, xf);
        for (const RaySet& k : sets) {
            const double engine = mrays(*k.st, k.any, kt, xf, reps);
            const double engine_single = mrays(*k.st, k.any, kt, single.xf, reps);
            const WalkResult w = time_stream_walk(*mesh, *k.st, k.any, kt, xf, reps, chunk ? chunk : k.st->count);
            std::printf("%-8s %9zu %10.2f %10.2f %10.2f %6.2fx %12.2f %8zu (%zu)\n", k.name, k.st->count, engine,
                        engine_single, w.mrays, w.mrays / std::max(engine, engine_single),
                        w.stats.nodes ? double(w.stats.node_rays) / double(w.stats.nodes) : 0.0, w.hits, w.differ);
        }
    }
    return 0;
}
