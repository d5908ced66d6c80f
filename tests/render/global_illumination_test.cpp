// Degree 6 (docs/global-illumination.md): light bounced between surfaces by path tracing, in
// both engines. The expected values are closed forms of the rendering equation for scenes
// simple enough to have one, not figures read off either engine.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "driver/render.h"
#include "render/sampling.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

constexpr EngineKind kEngines[] = {EngineKind::Stream, EngineKind::Recursive};

struct Stats {
    double mean[3] = {0, 0, 0};
    double sd[3] = {0, 0, 0};  ///< of one pixel's value, over the pixels
};
Stats pixel_stats(const Framebuffer& fb) {
    Stats s;
    const double n = double(fb.width) * fb.height;
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x)
            for (int c = 0; c < 3; ++c) s.mean[c] += fb.pixel(x, y)[c] / n;
    for (int y = 0; y < fb.height; ++y)
        for (int x = 0; x < fb.width; ++x)
            for (int c = 0; c < 3; ++c) s.sd[c] += (fb.pixel(x, y)[c] - s.mean[c]) * (fb.pixel(x, y)[c] - s.mean[c]) / n;
    for (double& v : s.sd) v = std::sqrt(v);
    return s;
}

double rmse(const Framebuffer& a, const Framebuffer& b) {
    double sum = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) sum += std::pow(double(a.pixel(x, y)[c]) - b.pixel(x, y)[c], 2);
    return std::sqrt(sum / (3.0 * a.width * a.height));
}

/// A small box of canonical shapes at degree 6: a red and a green wall, a white floor, back
/// wall and ceiling, a point light, a sky seen through the open front.
std::string box(int spp, int depth) {
    return "image width=24 height=24 spp=" + std::to_string(spp) + " depth=" + std::to_string(depth) +
           " degree=6 sampler=stratified\n"
           "background 0.3,0.35,0.4\n"
           "camera eye=0,1,4 look=0,1,0 up=0,1,0 fov=50\n"
           "light point pos=0,1.8,0.5 color=1,1,1\n"
           "plane color=0.8,0.8,0.8 diff=0.9\n"
           "plane color=0.8,0.8,0.8 diff=0.9 rotate_x=180 translate=0,2,0\n"
           "plane color=0.8,0.8,0.8 diff=0.9 rotate_x=90 translate=0,0,-1\n"
           "plane color=0.8,0.1,0.1 diff=0.9 rotate_z=-90 translate=-1,0,0\n"
           "plane color=0.1,0.8,0.1 diff=0.9 rotate_z=90 translate=1,0,0\n"
           "sphere color=0.9,0.9,0.5 diff=0.8 scale=0.4 translate=-0.3,0.4,-0.2\n";
}

/// Renders `text` with each engine (-j2) and hands the result to `check`.
template <class Check>
void in_both_engines(const std::string& text, const char* name, Check check) {
    for (EngineKind engine : kEngines) {
        CAPTURE(engine_name(engine));
        Parallelism par(2);
        check(render_scene(parse_scene(text, name), engine, par));
    }
}

}  // namespace

TEST_CASE("degree 6: a convex diffuse sphere under a uniform sky is rho L, at any spp, in both engines") {
    // Every cosine-sampled bounce off a convex surface escapes to the sky L, so each sample
    // brings rho L = (color x diff) L exactly: no noise, no ambient (degree 6 has none).
    const std::string text =
        "image width=16 height=16 spp=3 depth=4 degree=6\n"
        "ambient 0.5\n"
        "background 0.5,0.7,0.9\n"
        "camera eye=0,0,3 look=0,0,0 up=0,1,0 fov=60\n"
        "sphere color=0.8,0.6,0.4 diff=0.5 ambi=1\n";
    in_both_engines(text, "sky_sphere.cfg", [](const RenderResult& r) {
        const float* centre = r.image.pixel(8, 8);
        CHECK(centre[0] == doctest::Approx(0.8 * 0.5 * 0.5).epsilon(1e-5));
        CHECK(centre[1] == doctest::Approx(0.6 * 0.5 * 0.7).epsilon(1e-5));
        CHECK(centre[2] == doctest::Approx(0.4 * 0.5 * 0.9).epsilon(1e-5));
        const float* corner = r.image.pixel(0, 0);  // beside the sphere: the sky itself
        CHECK(corner[0] == doctest::Approx(0.5).epsilon(1e-6));
        CHECK(r.counts.diffuse > 0);
    });
}

TEST_CASE("degree 6: inside a closed emitting sphere, depth 2 gives Le (1 + rho + rho^2) exactly") {
    // Every path hits the sphere at generations 0, 1 and 2 and gathers Le at each, weighted by
    // rho^k; roulette starts at generation 2, whose hits spawn nothing at depth 2: no noise.
    const std::string text =
        "image width=8 height=8 spp=2 depth=2 degree=6\n"
        "camera eye=0,0,0 look=0,0,-1 up=0,1,0 fov=60\n"
        "sphere color=1,0.5,0.25 diff=0.5 emission=0.4,0.4,0.4 scale=2\n";
    const double rho[3] = {0.5, 0.25, 0.125};
    in_both_engines(text, "furnace.cfg", [&](const RenderResult& r) {
        for (int c = 0; c < 3; ++c) {
            CAPTURE(c);
            const double expected = 0.4 * (1 + rho[c] + rho[c] * rho[c]);
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 8; ++x) CHECK(r.image.pixel(x, y)[c] == doctest::Approx(expected).epsilon(1e-5));
        }
    });
}

TEST_CASE("degree 6: with Russian roulette and a deep cap, the closed sphere converges to Le / (1 - rho)") {
    // Depth 60: the truncated geometric tail is below 1e-9 of the sum. Roulette ends paths at
    // random; the mean over the image must fall within 4 standard errors of Le / (1 - rho).
    const std::string text =
        "image width=32 height=32 spp=16 depth=60 degree=6\n"
        "camera eye=0,0,0 look=0,0,-1 up=0,1,0 fov=60\n"
        "sphere color=1,0.8,0.6 diff=0.7 emission=0.3,0.3,0.3 scale=2\n";
    const double rho[3] = {0.7, 0.56, 0.42};
    in_both_engines(text, "furnace_rr.cfg", [&](const RenderResult& r) {
        const Stats s = pixel_stats(r.image);
        for (int c = 0; c < 3; ++c) {
            CAPTURE(c);
            const double expected = 0.3 / (1 - rho[c]);
            const double standard_error = s.sd[c] / std::sqrt(32.0 * 32.0);
            CHECK(s.sd[c] > 0);  // roulette is on: the pixels differ
            CHECK(std::abs(s.mean[c] - expected) < 4 * standard_error);
        }
    });
}

TEST_CASE("degree 6 keeps degree 5's direct and specular light where nothing is diffuse") {
    // Mirrors, glass and emission only (diff = 0), ambient 0, cut-off 0: the two degrees trace
    // the same rays to the same terms.
    const std::string text =
        "image width=24 height=16 spp=2 depth=5 cutoff=0\n"
        "ambient 0\n"
        "background 0.2,0.3,0.5\n"
        "camera eye=0,1,5 look=0,0.5,0 up=0,1,0 fov=45\n"
        "light point pos=2,4,3 color=1,1,1\n"
        "plane color=0.5,0.5,0.5 diff=0 refl=0.6\n"
        "sphere color=1,1,1 diff=0 trans=0.9 ior=1.5 fresnel=true translate=-0.8,1,0\n"
        "sphere color=1,1,1 diff=0 spec=0.8 shininess=40 refl=0.9 translate=0.9,1,0\n"
        "cube color=0.2,0.2,0.2 diff=0 emission=1,0.6,0.2 scale=0.3 translate=0,0.3,-1.5\n";
    for (EngineKind engine : kEngines) {
        CAPTURE(engine_name(engine));
        Parallelism par(2);
        Scene five = parse_scene(text + "image degree=5\n", "specular.cfg");
        Scene six = parse_scene(text + "image degree=6\n", "specular.cfg");
        const RenderResult a = render_scene(five, engine, par), b = render_scene(six, engine, par);
        CHECK(b.counts.diffuse == 0);
        CHECK(a.counts.total() == b.counts.total());
        double worst = 0;
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 24; ++x)
                for (int c = 0; c < 3; ++c)
                    worst = std::max(worst, double(std::abs(a.image.pixel(x, y)[c] - b.image.pixel(x, y)[c])));
        CHECK(worst < 1e-6);
    }
}

TEST_CASE("degree 6: both engines take the same paths in a box and agree to float precision on most pixels") {
    Parallelism par(2);
    const Scene s = parse_scene(box(4, 6), "box.cfg");
    const RenderResult stream = render_scene(s, EngineKind::Stream, par);
    const RenderResult recursive = render_scene(s, EngineKind::Recursive, par);
    // The same paths: the same rays of every kind, give or take a rare roulette draw that
    // lands on the other side of q in float and in double.
    CHECK(double(stream.counts.diffuse) == doctest::Approx(double(recursive.counts.diffuse)).epsilon(0.002));
    CHECK(double(stream.counts.shadow) == doctest::Approx(double(recursive.counts.shadow)).epsilon(0.002));
    int close = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            double d = 0;
            for (int c = 0; c < 3; ++c)
                d = std::max(d, double(std::abs(stream.image.pixel(x, y)[c] - recursive.image.pixel(x, y)[c])));
            close += d < 1e-3;
        }
    CHECK(close >= 24 * 24 * 95 / 100);
    CHECK(rmse(stream.image, recursive.image) < 0.01);
}

TEST_CASE("degree 6: the picture is the same for every thread count and ISA level") {
    const Scene s = parse_scene(box(4, 6), "box.cfg");
    Parallelism one(1), two(2);
    const RenderResult a = render_scene(s, EngineKind::Stream, one);
    const RenderResult b = render_scene(s, EngineKind::Stream, two);
    EngineOptions sse2;
    sse2.isa = Isa::Sse2;
    const RenderResult c = render_scene(s, EngineKind::Stream, two, nullptr, sse2);
    for (const RenderResult* other : {&b, &c}) {
        const std::string which = other == &b ? "-j2" : "sse2";
        CAPTURE(which);
        CHECK(other->counts.total() == a.counts.total());
        CHECK(std::equal(a.image.rgb.begin(), a.image.rgb.end(), other->image.rgb.begin()));
    }
    // The scalar shade path sums a hit's terms in another order (as at degree 5): the same
    // paths, pictures equal to rounding.
    EngineOptions scalar;
    scalar.shade = ShadeMode::Scalar;
    const RenderResult d = render_scene(s, EngineKind::Stream, two, nullptr, scalar);
    CHECK(d.counts.total() == a.counts.total());
    CHECK(rmse(a.image, d.image) < 1e-5);
    const RenderResult e = render_scene(s, EngineKind::Recursive, one);
    const RenderResult f = render_scene(s, EngineKind::Recursive, two);
    CHECK(std::equal(e.image.rgb.begin(), e.image.rgb.end(), f.image.rgb.begin()));
}

TEST_CASE("degree 6: the error falls at least as fast as spp^(-1/2)") {
    // Against a converged picture of the same box (1024 spp): each quadrupling of the samples
    // at least halves the RMSE (10 % slack for the noise of the estimate itself).
    Parallelism par(2);
    const RenderResult reference = render_scene(parse_scene(box(1024, 6), "box.cfg"), EngineKind::Stream, par);
    double last = 0;
    for (int spp : {4, 16, 64}) {
        CAPTURE(spp);
        const double e = rmse(render_scene(parse_scene(box(spp, 6), "box.cfg"), EngineKind::Stream, par).image,
                              reference.image);
        if (last > 0) CHECK(e <= 0.55 * last);
        last = e;
    }
}

TEST_CASE("degree 6: camera keys number the paths, corners and lower degrees keep their hashed keys") {
    // 16 spp: 4 bits for the sample; pixel 5, sample 3 is 5 x 16 + 3.
    CHECK(camera_key(6, 16, 5, 3) == 5u * 16u + 3u);
    CHECK(camera_key(6, 9, 5, 8) == 5u * 16u + 8u);  // 9 samples still take 4 bits
    CHECK(camera_key(5, 16, 5, 3) == light_key(5, 3));
    // An adaptive corner's sample number does not fit: its key must not be pixel 7's sample 0's.
    CHECK(camera_key(6, 16, 7, kCornerSampleNumber) == light_key(7, kCornerSampleNumber));
    CHECK(camera_key(6, 16, 7, kCornerSampleNumber) != camera_key(6, 16, 7, 0));
}
