// Timing program for the object hierarchy (docs/performance.md, "## BVH"). Not a test.
//
//   bvh_bench build N [-j J]          build time and memory for N random spheres
//   bvh_bench scaling [-j J] [N...]   1280x720, 1 spp, primary + shadow rays, stream engine,
//                                     N random spheres on a plane (default 1e2 .. 1e6)
//   bvh_bench traversal [N]           packet vs single-ray traversal per ray kind (one core)
//   bvh_bench threshold [-j J]        flat loops vs hierarchy for small N, both engines
#include <algorithm>
#include <chrono>
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

using namespace streamrt;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

struct SphereRec {
    double x, y, z, r;
};

/// N spheres on a jittered grid over a square field (as scripts/random_spheres.py, without its
/// quadratic overlap search), a checkered plane, two point lights, a camera looking down at
/// the whole field. Degree 5, depth 0: primary + shadow rays.
Scene random_spheres(std::size_t n, std::vector<SphereRec>* out = nullptr, std::uint32_t seed = 1) {
    Scene s;
    s.settings.width = 1280;
    s.settings.height = 720;
    s.settings.spp = 1;
    s.settings.depth = 0;
    s.settings.degree = 5;
    s.settings.background = {0.5, 0.65, 0.85};
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::size_t g = std::size_t(std::ceil(std::sqrt(double(n))));
    const double cell = 4.0, side = cell * double(g);
    s.camera.look_at = true;
    s.camera.eye = {0, 0.75 * side + 2, 0.85 * side + 2};
    s.camera.look = {0, 0, -0.05 * side};
    s.camera.fov = 45;
    s.lights.push_back({LightKind::Point, {-0.4 * side, side + 4, 0.6 * side}, {0, -1, 0}, {0.8, 0.8, 0.8}, 30});
    s.lights.push_back({LightKind::Point, {0.6 * side, 0.7 * side + 3, 0.2 * side}, {0, -1, 0}, {0.45, 0.45, 0.5}, 30});
    Object plane;
    plane.kind = ShapeKind::Plane;
    Material floor;
    floor.checker = true;
    floor.checker_color = {0.25, 0.25, 0.25};
    floor.cell = cell / 2;
    s.add_object(plane, floor, {});
    Material matte;
    matte.diff = 0.85;
    matte.spec = 0.3;
    for (std::size_t i = 0; i < n; ++i) {
        const double r = cell * (0.2 + 0.25 * u(rng));
        const double x = -side / 2 + cell * (double(i % g) + 0.5) + (cell / 2 - r) * (2 * u(rng) - 1);
        const double z = -side / 2 + cell * (double(i / g) + 0.5) + (cell / 2 - r) * (2 * u(rng) - 1);
        Object o;
        o.kind = ShapeKind::Sphere;
        o.color = {0.1 + 0.9 * u(rng), 0.1 + 0.9 * u(rng), 0.1 + 0.9 * u(rng)};
        o.md = glm::dmat4x3(translate_matrix({x, r, z}) * scale_matrix({r, r, r}));
        s.add_object(o, matte, {});
        if (out) out->push_back({x, r, z, r});
    }
    return s;
}

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

/// Rays of one kind for the kernels: primary (camera), secondary (mirror reflections at the
/// primary hits) and shadow (from the primary hits to the first light).
struct RaySet {
    RayStream rays;
    ShadowStream shadows;
};

int cmd_traversal(std::size_t n) {
    std::vector<SphereRec> sph;
    const Scene s = random_spheres(n, &sph);
    const CameraRays<float> cam = CameraRays<float>::from(s);
    const Isa isa = best_isa();
    const KernelTable& kt = kernel_table(isa);
    const AccelKernelTable& at = accel_kernel_table(isa);
    StreamAccel sa(s, accel::SceneBvh::build(s), accel::AccelConfig{});
    // Build the leaf objects view the same way StreamAccel does, by asking it to trace.
    const int W = s.settings.width, H = s.settings.height;
    constexpr std::size_t kChunk = 4096;  // as the stream engine's chunks (16x16 tiles x 16)
    std::vector<RayStream> prim, refl;
    std::vector<ShadowStream> shad;
    // Primary rays in 16x16 tiles (the engine's order), 16 tiles per chunk.
    std::vector<std::pair<int, int>> order;
    for (int ty = 0; ty < H; ty += 16)
        for (int tx = 0; tx < W; tx += 16)
            for (int y = ty; y < std::min(H, ty + 16); ++y)
                for (int x = tx; x < std::min(W, tx + 16); ++x) order.push_back({x, y});
    for (std::size_t c = 0; c < order.size(); c += kChunk) {
        RayStream r;
        const std::size_t m = std::min(kChunk, order.size() - c);
        r.reserve(m);
        for (std::size_t k = 0; k < m; ++k) {
            const Vec3f d = cam.direction(float(order[c + k].first) + 0.5f, float(order[c + k].second) + 0.5f);
            r.ox[k] = cam.origin.x, r.oy[k] = cam.origin.y, r.oz[k] = cam.origin.z;
            r.dx[k] = d.x, r.dy[k] = d.y, r.dz[k] = d.z;
            r.t_max[k] = INFINITY;
        }
        r.count = m;
        r.pad_tail();
        prim.push_back(r);
    }
    // Hits, then reflected and shadow rays.
    const Light& L = s.lights[0];
    for (RayStream& r0 : prim) {
        RayStream r = r0;
        AlignedVec<std::int32_t> obj(r.capacity(), -1);
        sa.closest(kt, view_of(r), obj.data(), true);
        RayStream rr;
        ShadowStream sh;
        rr.reserve(r.count);
        sh.reserve(r.count);
        for (std::size_t k = 0; k < r.count; ++k) {
            if (obj[k] < 0) continue;
            const Vec3f o{r.ox[k], r.oy[k], r.oz[k]}, d{r.dx[k], r.dy[k], r.dz[k]};
            const Vec3f p = o + d * r.t_max[k];
            Vec3f nrm{0, 1, 0};
            if (obj[k] > 0) {
                const SphereRec& q = sph[std::size_t(obj[k] - 1)];
                nrm = normalize(Vec3f{float(p.x - q.x), float(p.y - q.y), float(p.z - q.z)});
            }
            const Vec3f from = p + nrm * 1e-3f;
            const Vec3f refl_d = d - nrm * (2.f * dot(d, nrm));
            const std::size_t j = rr.count++;
            rr.ox[j] = from.x, rr.oy[j] = from.y, rr.oz[j] = from.z;
            rr.dx[j] = refl_d.x, rr.dy[j] = refl_d.y, rr.dz[j] = refl_d.z;
            rr.t_max[j] = INFINITY;
            const std::size_t i = sh.count++;
            const Vec3f to{float(L.pos.x - from.x), float(L.pos.y - from.y), float(L.pos.z - from.z)};
            sh.ox[i] = from.x, sh.oy[i] = from.y, sh.oz[i] = from.z;
            sh.dx[i] = to.x, sh.dy[i] = to.y, sh.dz[i] = to.z;
            sh.t_max[i] = 1.f;
        }
        rr.pad_tail();
        sh.pad_tail();
        refl.push_back(rr);
        shad.push_back(sh);
    }
    const auto time_closest = [&](std::vector<RayStream>& set, BvhClosestFn fn, const accel::SceneBvh& sb,
                                  const std::vector<KernelObject>& prims) {
        const AccelView view{sb.bvh.nodes.data(), prims.data()};
        double best = 1e30;
        std::size_t rays = 0;
        for (int rep = 0; rep < 3; ++rep) {
            rays = 0;
            double t = 0;
            for (const RayStream& r0 : set) {
                RayStream r = r0;
                AlignedVec<std::int32_t> obj(r.capacity(), -1);
                const double t0 = now();
                fn(view, view_of(r), obj.data());
                t += now() - t0;
                rays += r.count;
            }
            best = std::min(best, t);
        }
        return double(rays) / best / 1e6;
    };
    const auto time_any = [&](std::vector<ShadowStream>& set, BvhAnyFn fn, const accel::SceneBvh& sb,
                              const std::vector<KernelObject>& prims) {
        const AccelView view{sb.bvh.nodes.data(), prims.data()};
        double best = 1e30;
        std::size_t rays = 0;
        for (int rep = 0; rep < 3; ++rep) {
            rays = 0;
            double t = 0;
            for (const ShadowStream& r0 : set) {
                ShadowStream r = r0;
                const double t0 = now();
                fn(view, view_of(r));
                t += now() - t0;
                rays += r.count;
            }
            best = std::min(best, t);
        }
        return double(rays) / best / 1e6;
    };
    // The kernels need the leaf objects, laid out as StreamAccel does.
    auto sb = accel::SceneBvh::build(s);
    std::vector<KernelObject> prims;
    for (std::uint32_t k = 0; k < sb->bvh.prim_index.size(); ++k)
        prims.push_back(kernel_object(s, sb->bvh.prim_index[k], std::int32_t(k), glm::dvec3(0.0)));
    std::printf("traversal, N=%zu spheres, isa %s, one thread, Mrays/s (hierarchy only, plane excluded):\n", n,
                isa_name(isa));
    std::printf("  primary   packet %7.2f   single %7.2f\n", time_closest(prim, at.closest_packet, *sb, prims),
                time_closest(prim, at.closest_single, *sb, prims));
    std::printf("  reflected packet %7.2f   single %7.2f\n", time_closest(refl, at.closest_packet, *sb, prims),
                time_closest(refl, at.closest_single, *sb, prims));
    std::printf("  shadow    packet %7.2f   single %7.2f\n", time_any(shad, at.any_packet, *sb, prims),
                time_any(shad, at.any_single, *sb, prims));
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
