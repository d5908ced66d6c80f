// The SIMD generate kernel gives, at every ISA level, exactly the rays the scalar formulas
// give (pixel_sample + CameraRays::direction), the ones the recursive baseline also traces.
#include <doctest/doctest.h>

#include <vector>

#include "kernels/shade_job.h"
#include "kernels/every_isa.h"
#include "kernels/kernel_table.h"
#include "render/adaptive.h"
#include "render/camera_rays.h"
#include "render/sampling.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

/// Runs the generate kernel of every ISA level this machine supports on `job` (its output a
/// fresh stream of n rays) and hands each level's rays to check.
template <class Check>
void generate_at_every_isa(GenerateJob job, std::size_t n, Check&& check) {
    at_every_isa([&](Isa isa) {
        RayStream rays;
        rays.reserve(n);
        job.out = append_view(rays);
        kernel_table(isa).generate(job);
        check(rays);
    });
}

}  // namespace

TEST_CASE("generate kernel: same sample positions and directions as the scalar formulas, every ISA") {
    for (const char* sampler : {"stratified", "grid", "random"}) {
        for (int spp : {1, 2, 3, 4, 6, 16}) {
            CAPTURE(sampler);
            CAPTURE(spp);
            const Scene scene = parse_scene(std::string("image width=37 height=23 spp=") + std::to_string(spp) +
                                                " sampler=" + sampler +
                                                "\ncamera eye=1,2,6 look=0,0.5,0 up=0,1,0 fov=50\nsphere\n",
                                            "gen.cfg");
            const auto cam = CameraRays<float>::from(scene);
            const int cols = grid_columns(spp);
            // Pixels 5..17 of row 3 (a chunk that does not start at a multiple of any width).
            std::vector<float> px, py, cx, cy;
            std::vector<std::uint32_t> kp, ks;
            for (int x = 5; x < 18; ++x)
                for (int k = 0; k < spp; ++k) {
                    px.push_back(float(x));
                    py.push_back(3.f);
                    kp.push_back(std::uint32_t(3 * 37 + x));
                    ks.push_back(std::uint32_t(k));
                    cx.push_back(float(k % cols));
                    cy.push_back(float(k / cols));
                }
            const std::size_t n = px.size(), cap = simd::round_up_lanes(n);
            for (auto* v : {&px, &py, &cx, &cy}) v->resize(cap, 0.f);
            kp.resize(cap, 0);
            ks.resize(cap, 0);
            AlignedVec<float> a_px(px.begin(), px.end()), a_py(py.begin(), py.end()), a_cx(cx.begin(), cx.end()),
                a_cy(cy.begin(), cy.end());
            AlignedVec<std::uint32_t> a_kp(kp.begin(), kp.end()), a_ks(ks.begin(), ks.end());
            const GenerateJob job{n, a_px.data(), a_py.data(), a_cx.data(), a_cy.data(), a_kp.data(), a_ks.data(),
                                  int(scene.settings.pattern), spp > 1, float(cols), float(spp / cols),
                                  &cam, 1.f / float(spp), {}};
            generate_at_every_isa(job, n, [&](const RayStream& rays) {
                for (std::size_t i = 0; i < n; ++i) {
                    const PixelSample ps = pixel_sample(scene.settings.pattern, spp, kp[i], int(ks[i]));
                    CHECK(ps.x >= 0.f);
                    CHECK(ps.x < 1.f);
                    const Vec3f d = cam.direction(px[i] + ps.x, py[i] + ps.y);
                    CHECK(rays.dx[i] == d.x);
                    CHECK(rays.dy[i] == d.y);
                    CHECK(rays.dz[i] == d.z);
                    CHECK(rays.ox[i] == cam.origin.x);
                    CHECK(rays.wr[i] == 1.f / float(spp));
                }
            });
        }
    }
}

TEST_CASE("generate kernel: adaptive rounds take the scalar sequence's points, every ISA") {
    const Scene scene = parse_scene("image width=37 height=23 spp=64 adaptive=0.01\n"
                                    "camera eye=1,2,6 look=0,0.5,0 up=0,1,0 fov=50\nsphere\n",
                                    "gen.cfg");
    const auto cam = CameraRays<float>::from(scene);
    for (int r = 1; r <= 4; ++r) {
        CAPTURE(r);
        const SampleRun run = adaptive_round(r, 64);
        // Rays of pixels 5..9 of row 3: the round's samples of each, indices up to 63.
        std::vector<float> px, py;
        std::vector<std::uint32_t> kp, ks;
        for (int x = 5; x < 10; ++x)
            for (int k = 0; k < run.count; ++k) {
                px.push_back(float(x));
                py.push_back(3.f);
                kp.push_back(std::uint32_t(3 * 37 + x));
                ks.push_back(std::uint32_t(run.first + k));
            }
        const std::size_t n = px.size(), cap = simd::round_up_lanes(n);
        px.resize(cap, 0.f), py.resize(cap, 0.f), kp.resize(cap, 0), ks.resize(cap, 0);
        AlignedVec<float> a_px(px.begin(), px.end()), a_py(py.begin(), py.end()), unused(cap, 0.f);
        AlignedVec<std::uint32_t> a_kp(kp.begin(), kp.end()), a_ks(ks.begin(), ks.end());
        GenerateJob job{n, a_px.data(), a_py.data(), unused.data(), unused.data(), a_kp.data(), a_ks.data(),
                        int(SamplePattern::Stratified), true, 1.f, 1.f, &cam, 1.f, {}};
        job.sequence = true;
        generate_at_every_isa(job, n, [&](const RayStream& rays) {
            for (std::size_t i = 0; i < n; ++i) {
                const PixelSample ps = pixel_sample(SamplePattern::Stratified, run, kp[i], int(ks[i]) - run.first);
                const Vec3f d = cam.direction(px[i] + ps.x, py[i] + ps.y);
                CHECK(rays.dx[i] == d.x);
                CHECK(rays.dy[i] == d.y);
                CHECK(rays.dz[i] == d.z);
            }
        });
    }
}

TEST_CASE("stratified samples fill every lattice cell once") {
    const int spp = 12, cols = grid_columns(spp);
    CHECK(cols == 4);
    std::vector<int> seen(spp, 0);
    for (int k = 0; k < spp; ++k) {
        const PixelSample ps = pixel_sample(SamplePattern::Stratified, spp, 12345, k);
        const int cell = int(ps.y * 3) * cols + int(ps.x * cols);
        ++seen[std::size_t(cell)];
    }
    for (int c : seen) CHECK(c == 1);
    const PixelSample centre = pixel_sample(SamplePattern::Random, 1, 7, 0);
    CHECK(centre.x == 0.5f);
    CHECK(centre.y == 0.5f);
}
