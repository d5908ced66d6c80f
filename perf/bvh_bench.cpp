// Timing program for the object hierarchy (docs/performance.md, "## BVH"). Not a test.
//
//   bvh_bench build N [-j J]          build time and memory for N random spheres
//   bvh_bench scaling [-j J] [N...]   1280x720, 1 spp, primary + shadow rays, stream engine,
//                                     N random spheres on a plane (default 1e2 .. 1e6)
//   bvh_bench traversal [N]           packet vs single-ray traversal per ray kind (one core, median of 3)
//   bvh_bench threshold [-j J]        flat loops vs hierarchy for small N, both engines
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "scene/scene_bvh.h"
#include "kernels/accel_kernel_table.h"
#include "parallel/parallelism.h"
#include "render/camera_rays.h"
#include "driver/render.h"
#include "stream/stream_accel.h"
#include "stream/stream_renderer.h"
#include "sphere_field.h"

using namespace streamrt;
using namespace streamrt::perf;

namespace {

int arg_jobs(int& argc, char** argv) {
    int jobs = 2;
    for (int i = 1; i + 1 < argc; ++i)
        if (std::string(argv[i]) == "-j") {
            jobs = std::atoi(argv[i + 1]);
            for (int k = i; k + 2 < argc + 1; ++k) argv[k] = argv[k + 2];
            argc -= 2;
            break;
        }
    return jobs;
}

/// The hierarchy settings of the renders measured here: `mode`, and the build's cost model
/// from the environment (BVH_TRAVERSAL_COST, BVH_MAX_LEAF) when set, for tuning runs.
accel::AccelConfig bench_accel(accel::AccelMode mode = accel::AccelMode::Auto) {
    accel::AccelConfig config;
    config.mode = mode;
    if (const char* c = std::getenv("BVH_TRAVERSAL_COST")) config.build.traversal_cost = float(std::atof(c));
    if (const char* c = std::getenv("BVH_MAX_LEAF")) config.build.max_leaf = std::atoi(c);
    return config;
}

double render_seconds(const Scene& s, EngineKind e, Parallelism& par, int reps = 3,
                      accel::AccelMode mode = accel::AccelMode::Auto) {
    EngineOptions options;
    options.accel = bench_accel(mode);
    double best = 1e30;
    for (int r = 0; r < reps; ++r) best = std::min(best, render_scene(s, e, par, nullptr, options).seconds);
    return best;
}

int cmd_build(std::size_t n, int jobs) {
    Parallelism par(jobs);
    const Scene s = random_spheres(n);
    for (int r = 0; r < 3; ++r) {
        const double t0 = now();
        auto b = accel::SceneBvh::build(s);
        const double t1 = now();
        std::printf("build %zu objects, -j%d: %.3f s (boxes + SAH + collapse; SAH+collapse %.3f s), %zu wide nodes, "
                    "%zu leaves, %.1f bytes/object for nodes + index\n",
                    n, jobs, t1 - t0, b->bvh.stats.seconds, b->bvh.stats.wide_nodes, b->bvh.stats.leaves,
                    double(b->bvh.memory_bytes()) / double(n));
    }
    StreamAccel sa(s, accel::SceneBvh::build(s), accel::AccelConfig{});
    std::printf("stream engine hierarchy (nodes + index + leaf objects): %.1f bytes/object\n",
                double(sa.memory_bytes()) / double(n));
    return 0;
}

int cmd_scaling(std::vector<std::size_t> ns, int jobs) {
    if (ns.empty()) ns = {100, 1000, 10000, 100000, 1000000};
    Parallelism par(jobs);
    double base = 0;
    for (std::size_t n : ns) {
        const Scene s = random_spheres(n);
        const double t0 = now();
        StreamRenderer renderer(s, best_isa(), ShadeMode::Auto, 0, bench_accel());  // builds the stream scene and its hierarchy
        const double tb = now() - t0;
        double t = 1e30;
        RenderProgress progress;
        for (int rep = 0; rep < 3; ++rep) {
            const double t1 = now();
            renderer.render(par, &progress);
            t = std::min(t, now() - t1);
        }
        const double rays = double(progress.counts().total()) / 3;
        if (base == 0) base = t;
        std::printf("N=%8zu  stream 1280x720 1spp primary+shadow -j%d: render %.3f s (%.2f Mrays/s, %.0f rays), "
                    "ratio to first %.2f; scene + hierarchy set-up %.3f s\n",
                    n, jobs, t, rays / t / 1e6, rays, t / base, tb);
        std::fflush(stdout);
    }
    return 0;
}

int cmd_traversal(std::size_t n) {
    std::vector<SphereRec> sph;
    const Scene s = random_spheres(n, &sph);
    const Isa isa = best_isa();
    const KernelTable& kt = kernel_table(isa);
    const AccelKernelTable& at = accel_kernel_table(isa);
    StreamAccel sa(s, accel::SceneBvh::build(s), accel::AccelConfig{});
    SphereRays sets = sphere_rays(s, sph, sa, kt);
    std::vector<RayStream>& prim = sets.primary;
    std::vector<RayStream>& refl = sets.reflected;
    std::vector<ShadowStream>& shad = sets.shadow;
    // The kernels need the leaf objects, laid out as StreamAccel does.
    auto sb = accel::SceneBvh::build(s);
    const std::vector<KernelObject> prims = leaf_objects(s, *sb);
    const AccelView view{sb->bvh.nodes.data(), prims.data()};
    const auto closest = [&](std::vector<RayStream>& set, BvhClosestFn fn) { return time_closest(set, fn, view, 3).mrays; };
    const auto any = [&](std::vector<ShadowStream>& set, BvhAnyFn fn) { return time_any(set, fn, view, 3).mrays; };
    std::printf("traversal, N=%zu spheres, isa %s, one thread, Mrays/s (hierarchy only, plane excluded):\n", n,
                isa_name(isa));
    std::printf("  primary   packet %7.2f   single %7.2f\n", closest(prim, at.closest_packet),
                closest(prim, at.closest_single));
    std::printf("  reflected packet %7.2f   single %7.2f\n", closest(refl, at.closest_packet),
                closest(refl, at.closest_single));
    std::printf("  shadow    packet %7.2f   single %7.2f\n", any(shad, at.any_packet), any(shad, at.any_single));
    return 0;
}

int cmd_threshold(int jobs) {
    Parallelism par(jobs);
    std::printf("N, stream flat s, stream bvh s, recursive flat s, recursive bvh s (1280x720, primary+shadow, -j%d)\n",
                jobs);
    for (std::size_t n : {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 64}) {
        const Scene s = random_spheres(n);
        double t[4];
        int k = 0;
        for (EngineKind e : {EngineKind::Stream, EngineKind::Recursive})
            for (accel::AccelMode m : {accel::AccelMode::Flat, accel::AccelMode::Bvh})
                t[k++] = render_seconds(s, e, par, e == EngineKind::Stream ? 5 : 2, m);
        std::printf("%3zu  %.4f  %.4f   %.4f  %.4f\n", n, t[0], t[1], t[2], t[3]);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const int jobs = arg_jobs(argc, argv);
    const std::string cmd = argc > 1 ? argv[1] : "";
    if (cmd == "build" && argc > 2) return cmd_build(std::size_t(std::atof(argv[2])), jobs);
    if (cmd == "scaling") {
        std::vector<std::size_t> ns;
        for (int i = 2; i < argc; ++i) ns.push_back(std::size_t(std::atof(argv[i])));
        return cmd_scaling(ns, jobs);
    }
    if (cmd == "traversal") return cmd_traversal(argc > 2 ? std::size_t(std::atof(argv[2])) : 10000);
    if (cmd == "threshold") return cmd_threshold(jobs);
    std::fprintf(stderr, "usage: bvh_bench build N | scaling [N...] | traversal [N] | threshold   [-j J]\n");
    return 2;
}
