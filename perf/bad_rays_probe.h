#pragma once
// Degenerate rays through every intersection kernel (closest and any hit, every shape kind):
// rays whose origin or direction components are zero, denormal, huge, infinite or NaN must get
// a definite answer (a miss, or a finite positive t with a valid object) and must not cost
// more than twice as much as ordinary rays. Shared by perf/bad_rays.cpp (the figure in
// docs/stability.md) and tests/stress/bad_rays_test.cpp (the assertion).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "core/transform.h"
#include "kernels/kernel_table.h"
#include "simd/lanes.h"

namespace streamrt::probe {

struct Rays {
    std::size_t n = 0;
    simd::AlignedVec<float> ox, oy, oz, dx, dy, dz, t;
    std::vector<std::int32_t> object;
    explicit Rays(std::size_t count) : n(count) {
        const std::size_t cap = simd::round_up_lanes(count) + simd::kMaxLanes;
        for (auto* a : {&ox, &oy, &oz, &dx, &dy, &dz, &t}) a->assign(cap, 0.f);
        object.assign(cap, -1);
    }
    void reset_t(float v) {
        std::fill(t.begin(), t.end(), -1.f);  // padding lanes: closed
        std::fill(t.begin(), t.begin() + std::ptrdiff_t(n), v);
        std::fill(object.begin(), object.end(), -1);
    }
    RayView view() { return {n, ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), t.data()}; }
};

/// n rays around a unit-scale scene; with `degenerate`, every ray has one to three components
/// replaced by 0, a denormal, a huge value, +-inf or NaN.
inline Rays make_rays(std::size_t n, bool degenerate, unsigned seed = 7) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float bad[] = {0.f, -0.f, 1e-40f, -3e-42f, 1e30f, -3e38f, std::numeric_limits<float>::max(), inf, -inf, nan};
    Rays r(n);
    for (std::size_t i = 0; i < n; ++i) {
        float c[6] = {4 * u(rng), 4 * u(rng), 6 + u(rng), 0.3f * u(rng), 0.3f * u(rng), -1.f};
        if (degenerate) {
            const int k = 1 + int(rng() % 3);
            for (int j = 0; j < k; ++j) c[rng() % 6] = bad[rng() % (sizeof bad / sizeof bad[0])];
            if (i % 7 == 0) c[3] = c[4] = c[5] = bad[rng() % 4];  // zero or denormal direction
        }
        r.ox[i] = c[0], r.oy[i] = c[1], r.oz[i] = c[2], r.dx[i] = c[3], r.dy[i] = c[4], r.dz[i] = c[5];
    }
    return r;
}

/// A few objects of one kind, placed around the origin.
inline std::vector<ObjectXf> make_objects(int count) {
    std::vector<ObjectXf> v;
    for (int k = 0; k < count; ++k) {
        const glm::dmat4 md = translate_matrix({-2.0 + k, 0.5 * (k % 3) - 0.5, -k * 0.5}) * rotate_y_matrix(20.0 * k) *
                              scale_matrix({0.5 + 0.1 * k, 0.6, 0.5});
        const glm::dmat4 mi = glm::inverse(md);
        ObjectXf o{};
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c) o.m[r * 4 + c] = float(mi[c][r]);
        o.param = 0.3f;
        o.id = k;
        v.push_back(o);
    }
    return v;
}

struct Result {
    std::size_t rays = 0, bad_answers = 0;
    double seconds = 0;  ///< best of `repeats`, closest + any over every kind
};

/// Runs closest and any hit of every shape kind over the rays; counts answers that are not
/// definite (a t that is not a miss and not finite and > 0, or an object id out of range).
inline Result run(const KernelTable& kt, Rays& rays, int repeats) {
    const std::vector<ObjectXf> objs = make_objects(6);
    const float inf = std::numeric_limits<float>::infinity();
    Result res;
    res.rays = rays.n;
    res.seconds = 1e30;
    for (int rep = 0; rep < repeats; ++rep) {
        double secs = 0;
        for (int k = 0; k < kShapeKindCount; ++k) {
            rays.reset_t(inf);
            auto t0 = std::chrono::steady_clock::now();
            kt.closest[k](rays.view(), rays.object.data(), objs.data(), objs.size());
            secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (rep == 0)
                for (std::size_t i = 0; i < rays.n; ++i) {
                    const float t = rays.t[i];
                    const std::int32_t id = rays.object[i];
                    const bool miss = id == -1 && t == inf;
                    const bool hit = id >= 0 && id < std::int32_t(objs.size()) && std::isfinite(t) && t > 0.f;
                    res.bad_answers += !(miss || hit);
                }
            rays.reset_t(1e6f);
            t0 = std::chrono::steady_clock::now();
            kt.any[k](rays.view(), objs.data(), objs.size());
            secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (rep == 0)
                for (std::size_t i = 0; i < rays.n; ++i) res.bad_answers += !(rays.t[i] == 1e6f || rays.t[i] == 0.f);
        }
        res.seconds = std::min(res.seconds, secs);
    }
    return res;
}

}  // namespace streamrt::probe
