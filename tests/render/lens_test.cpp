// Depth of field (camera aperture= focus=): the thin lens against its geometry, computed here
// independently: every ray of a pixel passes through the pinhole ray's point on the plane in
// focus, origins lie on the lens disc with a uniform spread, and the blur of an out-of-focus
// disk is the circle of confusion c = 2 A |d - f| / (f d) (screen units at unit distance),
// rendered by both engines.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "driver/render.h"
#include "kernels/shade_job.h"
#include "kernels/every_isa.h"
#include "kernels/kernel_table.h"
#include "render/camera_rays.h"
#include "render/sampling.h"
#include "scene/parser.h"
#include "render/look_at_oracle.h"
#include "stream/stream_renderer.h"

using namespace streamrt;

TEST_CASE("thin lens: rays of a pixel meet on the focus plane, origins fill the lens disc") {
    // An oblique look-at camera: eye (1,2,6) towards (0,0.5,0); focus 4.5, aperture 0.3.
    const Scene s = parse_scene("image width=40 height=30 spp=64\n"
                                "camera eye=1,2,6 look=0,0.5,0 up=0,1,0 fov=50 aperture=0.3 focus=4.5\nsphere\n",
                                "lens.cfg");
    const double A = 0.3, f = 4.5;
    const glm::dvec3 eye{1, 2, 6}, axis = glm::normalize(glm::dvec3{0, 0.5, 0} - eye);
    const auto cam = CameraRays<double>::from(s);
    REQUIRE(cam.has_lens());
    for (const auto& [x, y] : {std::pair{0, 0}, std::pair{20, 15}, std::pair{39, 7}}) {
        CAPTURE(x);
        CAPTURE(y);
        const std::uint64_t pixel = std::uint64_t(y) * 40 + std::uint64_t(x);
        // The pinhole ray of the pixel centre meets the plane dot(q - eye, axis) = f at:
        const Vec3d pin = cam.direction(x + 0.5, y + 0.5);
        const Vec3d pin_axis = to_vec(axis);
        const Vec3d focus_point = to_vec(eye) + pin * (f / dot(pin, pin_axis));
        double sum_r2 = 0, max_r = 0;
        Vec3d mean{0, 0, 0};
        for (int k = 0; k < 64; ++k) {
            const PixelSample ls = lens_sample(SamplePattern::Stratified, 64, pixel, k);
            Vec3d o, d;
            cam.lens_ray(x + 0.5, y + 0.5, double(ls.x), double(ls.y), o, d);
            const Vec3d off = o - to_vec(eye);
            CHECK(std::fabs(dot(off, pin_axis)) < 1e-12);  // the lens is perpendicular to the axis
            const double r = length(off);
            CHECK(r <= A * (1 + 1e-12));
            sum_r2 += r * r;
            max_r = std::max(max_r, r);
            mean = mean + off;
            CHECK(length(d) == doctest::Approx(1.0).epsilon(1e-12));
            // Where this ray crosses the focus plane:
            const double t = (f - dot(off, pin_axis)) / dot(d, pin_axis);
            const Vec3d q = o + d * t;
            CHECK(length(q - focus_point) < 1e-9);
        }
        // Uniform on a disc of radius A: E[r^2] = A^2 / 2, mean at the centre.
        CHECK(sum_r2 / 64 == doctest::Approx(A * A / 2).epsilon(0.03));
        CHECK(length(mean * (1.0 / 64)) < 0.03 * A);
        CHECK(max_r > 0.9 * A);
    }
}

TEST_CASE("thin lens: focus defaults to the look point (look-at) and to the screen plane (explicit)") {
    // Look-at: the centre ray's focus point is `look` itself (distance |look - eye| = 5).
    const Scene a = parse_scene("image width=11 height=11\ncamera eye=0,3,4 look=0,0,0 aperture=0.5\nsphere\n", "l.cfg");
    const auto ca = CameraRays<double>::from(a);
    for (const auto& [lx, ly] : {std::pair{1.0, 0.0}, std::pair{-0.3, 0.8}}) {
        Vec3d o, d;
        ca.lens_ray(5.5, 5.5, lx, ly, o, d);
        const double t = -o.y / d.y;  // the ray reaches y = 0 ...
        CHECK(std::fabs(o.x + t * d.x) < 1e-9);  // ... at look = (0,0,0)
        CHECK(std::fabs(o.z + t * d.z) < 1e-9);
    }
    // Explicit: Md = translate(0,0,2) scale(1,1,3): eye Md (0,0,1) = (0,0,5), screen plane
    // z = 2, |Md (0,0,-1)| = 3: screen point (0.5, 0, 0) maps to (0.5, 0, 2) and is in focus.
    const Scene b = parse_scene("image width=4 height=4\ncamera df=3 translate=0,0,2 aperture=0.25\nsphere\n", "e.cfg");
    const auto cb = CameraRays<double>::from(b);
    CHECK(cb.origin.z == doctest::Approx(5.0));
    Vec3d o, d;
    cb.lens_ray(3.0, 2.0, 0.6, -0.7, o, d);  // image (3, 2) of 4x4 = screen (0.5, 0)
    const double t = (2.0 - o.z) / d.z;
    CHECK(o.x + t * d.x == doctest::Approx(0.5).epsilon(1e-12));
    CHECK(std::fabs(o.y + t * d.y) < 1e-12);
}

TEST_CASE("thin lens: the lens cells of a pixel's samples are a permutation of the lattice") {
    for (int spp = 1; spp <= 40; ++spp)
        for (std::uint32_t pixel : {0u, 1u, 77u, 123456u}) {
            CAPTURE(spp);
            const int cols = grid_columns(spp);
            std::vector<int> seen(std::size_t(spp), 0);
            const LensCells cells(spp, pixel);
            for (int k = 0; k < spp; ++k) {
                int cx, cy;
                cells.cell(k, cx, cy);
                REQUIRE(cx >= 0);
                REQUIRE(cx < cols);
                REQUIRE(cy >= 0);
                REQUIRE(cy * cols + cx < spp);
                ++seen[std::size_t(cy * cols + cx)];
            }
            for (int c : seen) CHECK(c == 1);
        }
    // The pairing differs from pixel to pixel (not the identity everywhere).
    int moved = 0;
    for (std::uint32_t pixel = 0; pixel < 16; ++pixel) {
        int cx, cy;
        LensCells(16, pixel).cell(0, cx, cy);
        moved += (cx != 0 || cy != 0);
    }
    CHECK(moved >= 8);
}

TEST_CASE("thin lens: concentric map keeps the square's area fractions on the disc") {
    // Points of the square's inner half-size square [0.25,0.75]^2 land within radius 1/2,
    // the corners on the rim, and the map is uniform: the inner square (1/4 of the area)
    // covers the disc of radius 1/2 (1/4 of the disc).
    const PixelSample c = concentric_disc(0.5f, 0.5f);
    CHECK(c.x == 0.f);
    CHECK(c.y == 0.f);
    for (float u : {0.25f, 0.4f, 0.75f}) {
        const PixelSample p = concentric_disc(u, 0.25f);
        CHECK(std::hypot(p.x, p.y) == doctest::Approx(0.5).epsilon(1e-6));
    }
    const PixelSample e = concentric_disc(1.f, 0.5f);
    CHECK(e.x == doctest::Approx(1.0).epsilon(1e-6));
    CHECK(std::fabs(e.y) < 1e-6);
    const PixelSample corner = concentric_disc(0.f, 1.f);  // (-1, 1): radius 1 at 135 degrees
    CHECK(corner.x == doctest::Approx(-std::sqrt(0.5)).epsilon(1e-6));
    CHECK(corner.y == doctest::Approx(std::sqrt(0.5)).epsilon(1e-6));
}

TEST_CASE("thin lens: the generate(lens) kernel traces the scalar formulas' rays at every ISA level") {
    const Scene scene = parse_scene("image width=37 height=23 spp=6\n"
                                    "camera eye=1,2,6 look=0,0.5,0 up=0,1,0 fov=50 aperture=0.2 focus=3\nsphere\n",
                                    "gen.cfg");
    const int spp = 6, cols = grid_columns(spp);
    const auto cam = CameraRays<float>::from(scene);
    std::vector<float> px, py, cx, cy, lx, ly;
    std::vector<std::uint32_t> kp, ks;
    for (int x = 5; x < 18; ++x)
        for (int k = 0; k < spp; ++k) {
            const std::uint32_t pixel = std::uint32_t(3 * 37 + x);
            int a, b;
            LensCells(spp, pixel).cell(k, a, b);
            px.push_back(float(x)), py.push_back(3.f), kp.push_back(pixel), ks.push_back(std::uint32_t(k));
            cx.push_back(float(k % cols)), cy.push_back(float(k / cols)), lx.push_back(float(a)), ly.push_back(float(b));
        }
    const std::size_t n = px.size(), cap = simd::round_up_lanes(n);
    const auto aligned = [cap](std::vector<float> v) {
        v.resize(cap, 0.f);
        return AlignedVec<float>(v.begin(), v.end());
    };
    const AlignedVec<float> a_px = aligned(px), a_py = aligned(py), a_cx = aligned(cx), a_cy = aligned(cy),
                            a_lx = aligned(lx), a_ly = aligned(ly);
    kp.resize(cap, 0), ks.resize(cap, 0);
    const AlignedVec<std::uint32_t> a_kp(kp.begin(), kp.end()), a_ks(ks.begin(), ks.end());
    at_every_isa([&](Isa isa) {
        RayStream rays;
        rays.reserve(n);
        GenerateJob job{n, a_px.data(), a_py.data(), a_cx.data(), a_cy.data(), a_kp.data(), a_ks.data(),
                        int(scene.settings.pattern), true, float(cols), float(spp / cols), &cam, 1.f / float(spp),
                        append_view(rays), a_lx.data(), a_ly.data()};
        kernel_table(isa).generate_lens(job);
        for (std::size_t i = 0; i < n; ++i) {
            const PixelSample ps = pixel_sample(scene.settings.pattern, spp, kp[i], int(ks[i]));
            const PixelSample ls = lens_sample(scene.settings.pattern, spp, kp[i], int(ks[i]));
            Vec3f o, d;
            cam.lens_ray(px[i] + ps.x, py[i] + ps.y, ls.x, ls.y, o, d);
            CHECK(rays.ox[i] == o.x);
            CHECK(rays.oy[i] == o.y);
            CHECK(rays.oz[i] == o.z);
            CHECK(rays.dx[i] == d.x);
            CHECK(rays.dy[i] == d.y);
            CHECK(rays.dz[i] == d.z);
        }
        // Independently of the lens and sample templates the kernel shares, from the docs'
        // thin lens (camera aperture=0.2 focus=3) on the docs' look-at camera written in the
        // test: every ray leaves the lens disc (radius 0.2 around the eye, across the view) and
        // crosses the plane in focus, 3 along the view, where the pinhole ray of a point in its
        // pixel's lattice cell does (cell k % 3, k / 3 of 3 x 2); a pixel's 6 rays leave from
        // 6 different points of the lens.
        const test::LookAtOracle oracle({1, 2, 6}, {0, 0.5, 0}, {0, 1, 0}, 50, 37, 23);
        REQUIRE(cols == 3);
        for (std::size_t i = 0; i < n; ++i) {
            const glm::dvec3 o{rays.ox[i], rays.oy[i], rays.oz[i]}, dir{rays.dx[i], rays.dy[i], rays.dz[i]};
            CHECK(glm::length(o - oracle.eye) <= 0.2 * (1 + 1e-6));
            CHECK(std::fabs(glm::dot(o - oracle.eye, oracle.forward)) < 1e-6);
            const glm::dvec2 at = oracle.image_position(o, dir, 3.0);
            const double cx0 = px[i] + (ks[i] % 3) / 3.0, cy0 = 3.0 + (ks[i] / 3) / 2.0, eps = 1e-4;
            CHECK(at.x > cx0 - eps);
            CHECK(at.x < cx0 + 1.0 / 3 + eps);
            CHECK(at.y > cy0 - eps);
            CHECK(at.y < cy0 + 0.5 + eps);
        }
        for (std::size_t first = 0; first + spp <= n; first += spp)
            for (std::size_t i = first; i < first + spp; ++i)
                for (std::size_t j = first; j < i; ++j)
                    CHECK((rays.ox[i] != rays.ox[j] || rays.oy[i] != rays.oy[j] || rays.oz[i] != rays.oz[j]));
    });
}

namespace {
/// A white disk of radius rho facing the canonical camera (eye (0,0,1), screen [-1,1]^2 at
/// z = 0) at distance d from the eye, flat colour on black, N x N pixels (1 screen unit =
/// N/2 pixels), both engines.
std::vector<Framebuffer> render_disk(int n, int spp, double aperture, double focus, double rho, double d) {
    const std::string text = "image width=" + std::to_string(n) + " height=" + std::to_string(n) +
                             " spp=" + std::to_string(spp) + " degree=0 depth=0\ncamera aperture=" +
                             std::to_string(aperture) + " focus=" + std::to_string(focus) +
                             "\ndisk color=1,1,1 scale=" + std::to_string(rho) +
                             " rotate_x=90 translate=0,0," + std::to_string(1.0 - d) + "\n";
    const Scene scene = parse_scene(text, "coc.cfg");
    std::vector<Framebuffer> out;
    for (EngineKind e : {EngineKind::Recursive, EngineKind::Stream}) {
        Parallelism par(1);
        out.push_back(render_scene(scene, e, par).image);
    }
    return out;
}
}  // namespace

TEST_CASE("thin lens: an out-of-focus disk blurs over exactly its circle of confusion, both engines") {
    // Derivation (canonical camera, screen at unit distance): a ray from lens point a through
    // the focus-plane point of screen position x (at depth f: x f) crosses depth d at
    // a + (x f - a) d / f; pixel x sees the disk of radius rho at depth d from lens point a iff
    // |x d - a (d/f - 1)| <= rho. Over the lens disc |a| <= A the pixel is fully covered when
    // |x| <= (rho - A |d - f| / f) / d and never covered when |x| > (rho + A |d - f| / f) / d:
    // the edge of the disk's image (rho / d) blurs over +-A |d - f| / (f d), a circle of
    // confusion of diameter c = 2 A |d - f| / (f d). Each lens point sees a whole disk image
    // of radius rho / d, so the total light is that of the sharp image.
    const int n = 101, spp = 64;
    const double A = 0.5, f = 2.0, d = 4.0, rho = 1.2;
    const double scale = n / 2.0;                                    // pixels per screen unit
    const double inner = (rho - A * std::fabs(d - f) / f) / d * scale;  // 8.84 px
    const double outer = (rho + A * std::fabs(d - f) / f) / d * scale;  // 21.46 px
    const std::vector<Framebuffer> images = render_disk(n, spp, A, f, rho, d);
    for (std::size_t e = 0; e < images.size(); ++e) {
        CAPTURE(e);
        const Framebuffer& fb = images[e];
        double total = 0;
        int partial = 0, band = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                // Pixel centres relative to the image centre; samples fall within 0.71 px.
                const double r = std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0);
                const float v = fb.pixel(x, y)[0];
                total += v;
                if (r + 0.75 < inner) CHECK(v == doctest::Approx(1.0).epsilon(1e-6));
                if (r - 0.75 > outer) CHECK(v == 0.f);
                if (r > inner + 2.5 && r < outer - 2.5) {  // well inside the blur band
                    ++band;
                    partial += v > 0.f && v < 0.999f;
                }
            }
        CHECK(band > 300);
        CHECK(partial == band);
        const double sharp = M_PI * (rho / d * scale) * (rho / d * scale);  // 721 px
        CHECK(total == doctest::Approx(sharp).epsilon(0.01));
    }
    // In focus (d = f), the same disk has a sharp edge: at most a pixel's width of partial
    // coverage around rho / f.
    const double edge = rho / f * scale;
    for (const Framebuffer& fb : render_disk(n, spp, A, f, rho, f))
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double r = std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0);
                const float v = fb.pixel(x, y)[0];
                if (r + 1.0 < edge) CHECK(v == doctest::Approx(1.0).epsilon(1e-6));
                if (r - 1.0 > edge) CHECK(v == 0.f);
            }
}

TEST_CASE("thin lens: the stream pipeline builds generate(lens) only for a camera with an aperture") {
    const auto stages = [](const std::string& cam) {
        const Scene s = parse_scene("image width=8 height=8 spp=4\n" + cam + "\nsphere\n", "p.cfg");
        return StreamRenderer(s, best_isa()).built_stages().front();
    };
    CHECK(stages("camera eye=0,0,5 look=0,0,0 aperture=0.1") == "generate(jittered,lens)");
    CHECK(stages("camera eye=0,0,5 look=0,0,0") == "generate(jittered)");
    CHECK(stages("camera eye=0,0,5 look=0,0,0 aperture=0 focus=3") == "generate(jittered)");
}
