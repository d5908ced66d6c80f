// Google Benchmark micro-benchmarks of the stream engine's intersection kernels
// (docs/performance.md, "Kernel microbenchmarks"). Not a test.
//
//   build/perf/kernel_bench                         every kernel, every ISA this CPU runs
//   build/perf/kernel_bench --benchmark_filter=sphere/closest/avx512
//   build/perf/kernel_bench --benchmark_format=json --benchmark_out=build/perf/kernels.json
//
// BM_kernel/<shape>/<closest|any>/<isa>/<rays>/<objects>: kernel_table(isa).closest[kind] (or
// .any[kind]) on a packet of `rays` rays (16 .. 4096) against `objects` objects of that shape.
// Rays start on a square in front of the objects and aim at random points of their bounding
// box, so about half of them hit. Counters:
//   rays/s        rays through the kernel per second (each ray tested against every object)
//   tests/s       ray-object tests per second (rays/s x objects)
//   cycles/test   CPU time per ray-object test x the TSC frequency ("tsc_ghz" in the context,
//                 the nominal clock; turbo makes the true core cycles somewhat higher)
// BM_arith_limit/<isa>: the sphere kernel's floating-point mix (perf/arith_limit.h) on
// independent chains: the most ray-sphere tests per second the arithmetic units can do.
#include <benchmark/benchmark.h>
#include <x86intrin.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "arith_limit.h"
#include "kernels/kernel_table.h"
#include "shapes/shapes.h"
#include "simd/lanes.h"
#include "kernels/ray_stream.h"

using namespace streamrt;

namespace {

/// This thread's CPU time in seconds: cycles are counted on it, not on the wall clock, so that
/// time spent descheduled on a shared machine does not count.
double thread_cpu_seconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double measure_tsc_ghz() {
    const auto t0 = std::chrono::steady_clock::now();
    const unsigned long long c0 = __rdtsc();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const unsigned long long c1 = __rdtsc();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return double(c1 - c0) / s * 1e-9;
}

double tsc_ghz() {
    static const double g = measure_tsc_ghz();
    return g;
}


struct Fixture {
    RayStream rays;
    std::vector<float> t_max0;
    std::vector<std::int32_t> object;
    std::vector<ObjectXf> objs;
};

/// n_objs objects of one shape in a row along x (scaled by 0.5, unit spacing), rays from
/// z = 5 aimed at random points of the row's box, with the same seed every time.
Fixture make_fixture(ShapeKind kind, std::size_t n_rays, std::size_t n_objs) {
    Fixture f;
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    const float half = 0.5f * float(n_objs);
    f.rays.reserve(n_rays);
    f.rays.count = n_rays;
    for (std::size_t i = 0; i < n_rays; ++i) {
        const float ox = u(rng) * half, oy = u(rng), oz = 5.f;
        const float tx = u(rng) * half * 1.2f, ty = u(rng) * 0.7f, tz = u(rng) * 0.5f;
        float dx = tx - ox, dy = ty - oy, dz = tz - oz;
        const float l = std::sqrt(dx * dx + dy * dy + dz * dz);
        f.rays.ox[i] = ox, f.rays.oy[i] = oy, f.rays.oz[i] = oz;
        f.rays.dx[i] = dx / l, f.rays.dy[i] = dy / l, f.rays.dz[i] = dz / l;
        f.rays.t_max[i] = 1e30f;
    }
    f.rays.pad_tail();
    f.t_max0.assign(f.rays.t_max.begin(), f.rays.t_max.end());
    f.object.assign(f.rays.capacity(), -1);
    for (std::size_t k = 0; k < n_objs; ++k) {
        // Mi of "scale 0.5, translate (cx, 0, 0)"; a flat shape (no canonical y extent: the
        // plane, the disk) also rotate_x 90 first, so that its xz plane faces the rays.
        const float cx = -half + 0.5f + float(k);
        const CanonicalBounds b = canonical_bounds(kind, 0.3);
        const float upright[12] = {2, 0, 0, -2 * cx, 0, 2, 0, 0, 0, 0, 2, 0};
        const float facing[12] = {2, 0, 0, -2 * cx, 0, 0, 2, 0, 0, -2, 0, 0};  // canonical y = world z
        ObjectXf o{};
        std::copy_n(b.lo[1] == b.hi[1] ? facing : upright, 12, o.m);
        o.param = 0.3f;  // the torus's minor radius (unused by the others)
        o.id = std::int32_t(k);
        f.objs.push_back(o);
    }
    return f;
}

void BM_kernel(benchmark::State& state, Isa isa, ShapeKind kind, bool closest) {
    const std::size_t n_rays = std::size_t(state.range(0)), n_objs = std::size_t(state.range(1));
    Fixture f = make_fixture(kind, n_rays, n_objs);
    const KernelTable& kt = kernel_table(isa);
    const ClosestHitFn ch = kt.closest[int(kind)];
    const AnyHitFn ah = kt.any[int(kind)];
    RayView v = view_of(f.rays);
    const double c0 = thread_cpu_seconds();
    for (auto _ : state) {
        std::copy(f.t_max0.begin(), f.t_max0.end(), f.rays.t_max.begin());  // a fresh packet each time
        if (closest) ch(v, f.object.data(), f.objs.data(), n_objs);
        else ah(v, f.objs.data(), n_objs);
        benchmark::DoNotOptimize(f.rays.t_max.data());
        benchmark::ClobberMemory();
    }
    const double cycles = (thread_cpu_seconds() - c0) * tsc_ghz() * 1e9;
    const double rays = double(state.iterations()) * double(n_rays);
    state.counters["rays/s"] = benchmark::Counter(rays, benchmark::Counter::kIsRate);
    state.counters["tests/s"] = benchmark::Counter(rays * double(n_objs), benchmark::Counter::kIsRate);
    state.counters["cycles/test"] = cycles / (rays * double(n_objs));
    state.counters["lanes"] = kt.float_lanes;
}

void BM_arith_limit(benchmark::State& state, perf::MixRunner r) {
    const std::int64_t tests = 8 * 1024;  // packets of W lanes per call
    const double c0 = thread_cpu_seconds();
    for (auto _ : state) benchmark::DoNotOptimize(r.run(tests, perf::kSphereFma, perf::kSphereDiv, perf::kSphereSqrt));
    const double cycles = (thread_cpu_seconds() - c0) * tsc_ghz() * 1e9;
    const double lane_tests = double(state.iterations()) * double(tests) * r.lanes;
    state.counters["tests/s"] = benchmark::Counter(lane_tests, benchmark::Counter::kIsRate);
    state.counters["cycles/test"] = cycles / lane_tests;
    state.counters["flop/s"] =
        benchmark::Counter(lane_tests * (perf::kSphereFma + perf::kSphereDiv + perf::kSphereSqrt), benchmark::Counter::kIsRate);
    state.counters["lanes"] = r.lanes;
}

// FMA throughput alone (fma only): the peak the FMA units reach, in lane-FMAs per second.
void BM_fma_peak(benchmark::State& state, perf::MixRunner r) {
    const std::int64_t tests = 8 * 1024;
    const int n = 64;
    const double c0 = thread_cpu_seconds();
    for (auto _ : state) benchmark::DoNotOptimize(r.run(tests, n, 0, 0));
    const double cycles = (thread_cpu_seconds() - c0) * tsc_ghz() * 1e9;
    const double lane_fmas = double(state.iterations()) * double(tests) * n * r.lanes;
    state.counters["fma/s"] = benchmark::Counter(lane_fmas, benchmark::Counter::kIsRate);
    state.counters["vec_fma/cycle"] = lane_fmas / r.lanes / cycles;
}

void register_all() {
    const struct {
        Isa isa;
        perf::MixRunner runner;
    } levels[] = {{Isa::Sse2, perf::sse2::runner},
                  {Isa::Sse42, perf::sse42::runner},
                  {Isa::Avx2, perf::avx2::runner},
                  {Isa::Avx512, perf::avx512::runner}};
    for (const auto& l : levels) {
        if (!isa_supported(l.isa)) continue;
        const std::string isa = isa_name(l.isa);
        benchmark::RegisterBenchmark(("BM_fma_peak/" + isa).c_str(), BM_fma_peak, l.runner)->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("BM_arith_limit/" + isa).c_str(), BM_arith_limit, l.runner)
            ->Unit(benchmark::kMicrosecond);
    }
    for (const auto& l : levels) {
        if (!isa_supported(l.isa)) continue;
        const std::string isa = isa_name(l.isa);
        // Every registered canonical shape (shapes/shapes.h). Meshes have their own benchmark
        // (perf/mesh_bench.cpp): their kernel walks a per-mesh hierarchy rather than testing one
        // closed-form shape.
        CanonicalShapes::for_each([&](auto shape) {
            for (bool closest : {true, false}) {
                const std::string name =
                    std::string("BM_kernel/") + std::string(shape.name) + (closest ? "/closest/" : "/any/") + isa;
                auto* b = benchmark::RegisterBenchmark(name.c_str(), BM_kernel, l.isa, shape.kind, closest);
                for (int rays : {16, 64, 256, 1024, 4096})
                    for (int objs : {1, 8}) b->Args({rays, objs});
                b->ArgNames({"rays", "objs"});
            }
        });
    }
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::AddCustomContext("tsc_ghz", std::to_string(tsc_ghz()));
    benchmark::AddCustomContext("best_isa", isa_name(best_isa()));
    register_all();
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
