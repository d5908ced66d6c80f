// The SIMD generate kernel gives, at every ISA level, exactly the rays the scalar formulas
// give (pixel_sample + CameraRays::direction), the ones the recursive baseline also traces;
// and those rays are the docs' camera's, held against a camera written in the test
// (render/look_at_oracle.h) and directions worked out by hand, since the kernel and the scalar
// formulas are one template and would agree on a mistake.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "kernels/shade_job.h"
#include "kernels/every_isa.h"
#include "kernels/kernel_table.h"
#include "render/adaptive.h"
#include "render/camera_rays.h"
#include "render/sampling.h"
#include "scene/parser.h"
#include "render/look_at_oracle.h"

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
            const test::LookAtOracle oracle({1, 2, 6}, {0, 0.5, 0}, {0, 1, 0}, 50, 37, 23);
            const int cols = grid_columns(spp), rows = spp / cols;
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
                    // Independently: the ray leaves the eye and crosses the screen inside its
                    // pixel, in its sample's lattice cell (stratified and grid: cell k % cols,
                    // k / cols of a cols x rows lattice), at the cell's centre for grid. The
                    // tolerance is float rounding of a direction, a few 1e-6 pixels.
                    const glm::dvec3 o{rays.ox[i], rays.oy[i], rays.oz[i]}, dir{rays.dx[i], rays.dy[i], rays.dz[i]};
                    CHECK(glm::length(o - oracle.eye) < 1e-6);
                    const glm::dvec2 at = oracle.image_position(o, dir);
                    const std::string sampler_name = sampler;
                    const double x0 = px[i], y0 = 3.0, k = ks[i], eps = 1e-4;
                    double cx0 = x0, cx1 = x0 + 1, cy0 = y0, cy1 = y0 + 1;
                    if (sampler_name != "random") {
                        cx0 = x0 + std::fmod(k, cols) / cols, cx1 = cx0 + 1.0 / cols;
                        cy0 = y0 + std::floor(k / cols) / rows, cy1 = cy0 + 1.0 / rows;
                    }
                    CHECK(at.x > cx0 - eps);
                    CHECK(at.x < cx1 + eps);
                    CHECK(at.y > cy0 - eps);
                    CHECK(at.y < cy1 + eps);
                    if (sampler_name == "grid") {
                        CHECK(at.x == doctest::Approx((cx0 + cx1) / 2).epsilon(1e-6));
                        CHECK(at.y == doctest::Approx((cy0 + cy1) / 2).epsilon(1e-6));
                    }
                }
                if (std::string(sampler) == "grid" && (spp == 1 || spp == 4)) {
                    // Worked out by hand from the docs' camera (eye 1,2,6, look 0,0.5,0, fov 50,
                    // 37 x 23): the centre of pixel (5, 3), and grid spp 4's samples 3 and 0 of
                    // pixel (17, 3), at (17.75, 3.75) and (17.25, 3.25).
                    const auto near = [&](std::size_t i, double x, double y, double z) {
                        CHECK(rays.dx[i] == doctest::Approx(x).epsilon(1e-6));
                        CHECK(rays.dy[i] == doctest::Approx(y).epsilon(1e-6));
                        CHECK(rays.dz[i] == doctest::Approx(z).epsilon(1e-6));
                    };
                    if (spp == 1) near(0, -0.5887027, 0.0642208, -0.8057945);
                    if (spp == 4) near(12 * 4 + 3, -0.1926126, 0.0626370, -0.9792737);
                    if (spp == 4) near(12 * 4 + 0, -0.2110291, 0.0808660, -0.9741291);
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
    const test::LookAtOracle oracle({1, 2, 6}, {0, 0.5, 0}, {0, 1, 0}, 50, 37, 23);
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
            // Independently (docs/adaptive-sampling.md): round r >= 1 of a cap of 64 is the
            // aligned block [2^(r+1), 2^(r+2)) of the pixel's (0,2)-sequence, 2^(r+1) points
            // that cover the pixel evenly: every one of its elementary cells of area 2^-(r+1)
            // (2^a columns by 2^(r+1-a) rows, each a) holds exactly one of them. The points are
            // read back from the rays through the docs' camera, written in the test.
            const int m = r + 1, count = 1 << m;
            REQUIRE(run.count == count);
            for (int x = 5; x < 10; ++x) {
                std::vector<glm::dvec2> points;
                for (std::size_t i = 0; i < n; ++i)
                    if (int(px[i]) == x) {
                        const glm::dvec2 at = oracle.image_position({rays.ox[i], rays.oy[i], rays.oz[i]},
                                                                    {rays.dx[i], rays.dy[i], rays.dz[i]});
                        points.push_back({at.x - x, at.y - 3.0});
                    }
                REQUIRE(int(points.size()) == count);
                for (int a = 0; a <= m; ++a) {
                    const int columns = 1 << a, rows = 1 << (m - a);
                    std::vector<int> seen(std::size_t(count), 0);
                    for (const glm::dvec2& q : points) {
                        const int cx = std::clamp(int(std::floor(q.x * columns)), 0, columns - 1);
                        const int cy = std::clamp(int(std::floor(q.y * rows)), 0, rows - 1);
                        ++seen[std::size_t(cy * columns + cx)];
                    }
                    CAPTURE(x);
                    CAPTURE(a);
                    for (const int c : seen) CHECK(c == 1);
                }
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
