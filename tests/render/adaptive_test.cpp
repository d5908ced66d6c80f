// Adaptive sampling (render/adaptive.h, driver/adaptive_render.*; docs/adaptive-sampling.md):
// the rounds, the error estimate against hand-computed values, and rendered pictures that
// depend on nothing but the pixels: -j, the whole image or one tile at a time, both engines;
// the cap, the threshold's monotonicity, the time limit and the image target.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "driver/render.h"
#include "parallel/parallelism.h"
#include "render/adaptive.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

// A mirror sphere and a glass one over a checkered floor, a point light (hard shadow edges):
// flat pixels, edges and reflected edges.
const char* kScene =
    "image width=48 height=32 spp=32 depth=3 degree=5\n"
    "camera eye=0,1.5,6 look=0,0,0\n"
    "light point pos=4,8,5\n"
    "sphere translate=-1,0,0 refl=0.6 diff=0.4\nsphere translate=1.2,0,0 trans=0.7 ior=1.5 diff=0.3\n"
    "plane translate=0,-1,0 checker=0.1,0.1,0.1 cell=0.5\n";

Scene adaptive_scene(double threshold, int cap = 32) {
    Scene sc = parse_scene(kScene, "adaptive.cfg");
    sc.settings.adaptive = threshold;
    sc.settings.spp = cap;
    return sc;
}

RenderResult render(const Scene& sc, EngineKind engine, int jobs, const AdaptiveStop& stop = {}) {
    EngineOptions options;
    options.adaptive_stop = stop;
    Parallelism par(jobs);
    auto prepared = prepare_render(sc, engine, options);
    return render_prepared(*prepared, par);
}

/// The picture rendered one tile at a time, each tile alone (shards, MPI ranks,
/// checkpoints): its ring's first round taken by itself.
Framebuffer render_tile_by_tile(const Scene& sc, EngineKind engine) {
    EngineOptions options;
    auto prepared = prepare_render(sc, engine, options);
    Framebuffer tiled(sc.settings.width, sc.settings.height);
    for (int i = 0; i < tile_count(sc.settings.width, sc.settings.height); ++i) {
        const Tile t = tile_rect(sc.settings.width, sc.settings.height, i);
        std::vector<float> rgb(std::size_t(t.width() * t.height() * 3));
        RayCounts counts;
        prepared->render_tile(t, rgb.data(), counts, nullptr);
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x)
                std::copy_n(&rgb[std::size_t(((y - t.y0) * t.width() + (x - t.x0)) * 3)], 3, tiled.pixel(x, y));
    }
    return tiled;
}

/// Samples taken by pixel i (the sample map's first channel).
float samples_at(const RenderResult& r, std::size_t i) { return r.sample_map.rgb[i * 3]; }

}  // namespace

TEST_CASE("adaptive: rounds start with 4 samples and double up to the cap") {
    // cap 32: 4 | 4 | 8 | 16 | none (4 + 4 + 8 + 16 = 32).
    const int firsts[] = {0, 4, 8, 16};
    const int counts[] = {4, 4, 8, 16};
    for (int r = 0; r < 4; ++r) {
        CAPTURE(r);
        CHECK(adaptive_round(r, 32).first == firsts[r]);
        CHECK(adaptive_round(r, 32).count == counts[r]);
    }
    CHECK(adaptive_round(4, 32).count == 0);
    // A cap that is not a power of two: the last round is cut (cap 11: 4 | 4 | 3).
    CHECK(adaptive_round(1, 11).count == 4);
    CHECK(adaptive_round(2, 11).first == 8);
    CHECK(adaptive_round(2, 11).count == 3);
    CHECK(adaptive_round(3, 11).count == 0);
    // A cap below the first round's size: one round.
    CHECK(adaptive_round(0, 2).count == 2);
    CHECK(adaptive_round(1, 2).count == 0);
}

namespace {

/// Whether points [first, first + 2^m) of pixel `pixel`'s sequence put exactly one point in
/// every elementary interval of area 2^-m: each box [i / 2^a, (i + 1) / 2^a) x [j / 2^(m-a),
/// (j + 1) / 2^(m-a)), for every a in [0, m] (the definition of a (0,m,2)-net).
bool is_net(std::uint32_t pixel, std::uint32_t first, int m) {
    const std::uint32_t n = 1u << m;
    for (int a = 0; a <= m; ++a) {
        std::vector<int> filled(n, 0);
        for (std::uint32_t k = first; k < first + n; ++k) {
            const PixelSample s = sequence_sample(pixel, k);
            if (!(s.x >= 0.f && s.x < 1.f && s.y >= 0.f && s.y < 1.f)) return false;
            const auto i = std::uint32_t(s.x * float(1u << a)), j = std::uint32_t(s.y * float(1u << (m - a)));
            ++filled[(j << a) | i];
        }
        for (int c : filled)
            if (c != 1) return false;
    }
    return true;
}

}  // namespace

TEST_CASE("adaptive: each round is a block of the pixel's (0,2)-sequence, stratified alone and with the rounds before") {
    // Rounds after the corners double what a pixel holds: samples [4, 8), [8, 16), [16, 32),
    // [32, 64), each an aligned block of the sequence, taken from it with the stratified pattern.
    for (int r = 1; r <= 4; ++r) {
        CAPTURE(r);
        CHECK(adaptive_round(r, 64).first == 1 << (r + 1));
        CHECK(adaptive_round(r, 64).sequence);
        CHECK(uses_sequence(SamplePattern::Stratified, adaptive_round(r, 64)));
    }
    CHECK_FALSE(uses_sequence(SamplePattern::Random, adaptive_round(1, 64)));
    CHECK_FALSE(uses_sequence(SamplePattern::Stratified, SampleRun{0, 16}));  // uniform sampling
    CHECK_FALSE(uses_sequence(SamplePattern::Stratified, corner_run()));
    for (std::uint32_t pixel : {0u, 1u, 7u, 640u * 479u + 639u, 123456789u}) {
        CAPTURE(pixel);
        // Each round alone, and every prefix the rounds build (corners apart, [0, 2^m)).
        for (int m = 2; m <= 6; ++m) {
            CAPTURE(m);
            CHECK(is_net(pixel, 1u << m, m));  // the round [2^m, 2^(m+1))
            CHECK(is_net(pixel, 0, m));        // the prefix [0, 2^m)
        }
        // Neighbouring pixels scramble differently: their first points differ.
        CHECK(sequence_sample(pixel, 5u).x != sequence_sample(pixel + 1, 5u).x);
    }
    // pixel_sample draws an adaptive round from the sequence, and a uniform run from its lattice.
    const SampleRun round = adaptive_round(2, 64);
    CHECK(pixel_sample(SamplePattern::Stratified, round, 42, 3).x == sequence_sample(42u, 11u).x);
    CHECK(pixel_sample(SamplePattern::Stratified, round, 42, 3).y == sequence_sample(42u, 11u).y);
}

TEST_CASE("adaptive: the first round is the pixels' corners, each traced once") {
    // The hash key of a corner counts on the (width + 1)-wide corner lattice; a pixel's on the image.
    CHECK(sample_key(corner_run(), 3, 2, 10) == 2u * 11u + 3u);
    CHECK(sample_key(SampleRun{0, 4}, 3, 2, 10) == 2u * 10u + 3u);
    CHECK(pixel_sample(SamplePattern::Stratified, corner_run(), 25, 0).x == 0.f);
    CHECK(pixel_sample(SamplePattern::Stratified, corner_run(), 25, 0).y == 0.f);
    // The canonical camera (eye (0, 0, 1), screen [-1, 1]^2 in z = 0) before a white sphere of
    // radius 1.5 centred 4 away on the axis, flat colour: corner (i, j) of a 24 x 24 image,
    // at screen (-1 + 2i/24, 1 - 2j/24), sees the sphere when its distance to the centre of
    // the screen is below tan(asin(1.5 / 4)), so tan^2 = 0.140625 / 0.859375. With T above any
    // spread, every pixel stops after the first round at k/4, k its corners on the sphere
    // (four stratified samples would land at random across the silhouette).
    const char* sphere = "image width=24 height=24 spp=16 degree=0\ncamera\nsphere scale=1.5 translate=0,0,-3\n";
    Scene sc = parse_scene(sphere, "corners.cfg");
    sc.settings.adaptive = 10;
    const double tan2 = 0.140625 / 0.859375;
    const auto on_sphere = [&](int i, int j) {
        const double x = -1 + 2.0 * i / 24, y = 1 - 2.0 * j / 24, d = x * x + y * y - tan2;
        REQUIRE(std::abs(d) > 1e-3);  // no corner on the silhouette itself
        return d < 0;
    };
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(engine));
        const RenderResult r = render(sc, engine, 2);
        REQUIRE(r.adaptive);
        CHECK(r.counts.primary == 25u * 25u);  // (24 + 1)^2 corners, not 4 per pixel
        int straddling = 0;
        for (int j = 0; j < 24; ++j)
            for (int i = 0; i < 24; ++i) {
                CAPTURE(i);
                CAPTURE(j);
                const int k = on_sphere(i, j) + on_sphere(i + 1, j) + on_sphere(i, j + 1) + on_sphere(i + 1, j + 1);
                straddling += k > 0 && k < 4;
                const std::size_t p = std::size_t(j * 24 + i);
                CHECK(samples_at(r, p) == 4);
                CHECK(r.image.rgb[p * 3] == doctest::Approx(k / 4.0).epsilon(1e-6));
            }
        CHECK(straddling > 20);
    }
}

TEST_CASE("adaptive: the error estimate is the standard error of the mean, root mean square over R, G and B") {
    PixelTally t;
    CHECK(std::isinf(t.standard_error()));
    // Grey samples 1, 2, 3, 4 (every channel alike): mean 2.5, s^2 = (2.25 + 0.25 + 0.25 +
    // 2.25) / 3 = 5/3 in each channel, standard error sqrt(5/3 / 4).
    for (float v : {1.f, 2.f, 3.f, 4.f}) t.add(v, v, v);
    CHECK(t.n == 4);
    CHECK(t.mean().x == doctest::Approx(2.5).epsilon(1e-15));
    CHECK(t.standard_error() == doctest::Approx(std::sqrt(5.0 / 12.0)).epsilon(1e-12));
    // Pure red samples 0 and 1: s^2 = 1/2 in red, 0 in green and blue, mean 1/6; the standard
    // error sqrt(1/6 / 2) = sqrt(1/12).
    PixelTally red;
    red.add(0.f, 0.f, 0.f);
    red.add(1.f, 0.f, 0.f);
    CHECK(red.standard_error() == doctest::Approx(std::sqrt(1.0 / 12.0)).epsilon(1e-12));
    // A bright flat pixel has no spread: exactly zero, not rounding noise of two large sums.
    PixelTally flat;
    for (int i = 0; i < 64; ++i) flat.add(1000.1f, 1000.1f, 1000.1f);
    CHECK(flat.standard_error() == 0.0);
}

TEST_CASE("adaptive: corners of different colour and equal luminance are a spread") {
    // Two red corners (0.7152, 0, 0) and two green ones (0, 0.2126, 0): each of luminance
    // 0.2126 x 0.7152, so a spread of luminance alone is 0 and the pixel would stop at its
    // corners. Per channel: red s^2 = 4 x 0.3576^2 / 3 = 0.170507, green 4 x 0.1063^2 / 3 =
    // 0.015066, blue 0; mean 0.061858, standard error sqrt(0.061858 / 4) = 0.12436.
    PixelTally t;
    for (int i = 0; i < 4; ++i) t.add_corner(i < 2 ? 0.7152f : 0.f, i < 2 ? 0.f : 0.2126f, 0.f);
    CHECK(t.standard_error() == doctest::Approx(0.12436).epsilon(1e-4));
    CHECK(AdaptiveRule{0.01, 64}.above(t));
    // The image's estimate after a first round is the same standard error, squared.
    CHECK(t.image_error_squared() == doctest::Approx(0.12436 * 0.12436).epsilon(1e-3));
}

TEST_CASE("adaptive: the image's estimate compares a pixel's last round with the samples before it") {
    // Before any round: no spread, no share of the image's error.
    PixelTally t;
    CHECK(t.image_error_squared() == 0.0);
    // A first round of grey 1, 2, 3, 4: no round before it, so the standard error squared, 5/12.
    t.begin_round();
    for (float v : {1.f, 2.f, 3.f, 4.f}) t.add(v, v, v);
    CHECK(t.image_error_squared() == doctest::Approx(5.0 / 12.0).epsilon(1e-12));
    // A round that doubles the pixel: 4 samples of 3.5 against the 4 before (mean 2.5): the
    // halves differ by 1, so the mean of the two is off by about 1/2: (1/2)^2 = 0.25.
    t.begin_round();
    for (int i = 0; i < 4; ++i) t.add(3.5f, 3.5f, 3.5f);
    CHECK(t.n == 8);
    CHECK(t.image_error_squared() == doctest::Approx(0.25).epsilon(1e-12));
    // Halves that agree give 0, whatever the spread inside each (stratified halves of an edge).
    PixelTally edge;
    for (float v : {0.f, 1.f, 0.f, 1.f}) edge.add(v, v, v);
    edge.begin_round();
    for (float v : {1.f, 0.f, 1.f, 0.f}) edge.add(v, v, v);
    CHECK(edge.image_error_squared() == 0.0);
    CHECK(edge.standard_error() > 0.1);  // the rule's estimate still sees the spread
    // A last round cut at the cap (8 + 3 samples) has no equal halves: the standard error.
    edge.begin_round();
    for (float v : {1.f, 0.f, 1.f}) edge.add(v, v, v);
    CHECK(edge.image_error_squared() == doctest::Approx(edge.standard_error() * edge.standard_error()).epsilon(1e-12));
}

TEST_CASE("adaptive: a pixel's corners read without a tally give add_corner's values, to the bit") {
    // The neighbour rule and the final pass (driver/adaptive_render.cpp) read a pixel that
    // stopped at its corners as a CornerQuad: nothing may tell it from the tally.
    const float c[4][3] = {{0.9f, 0.1f, 0.3f}, {0.25f, 0.5f, 0.125f}, {0.0f, 0.0f, 0.0f}, {1.5f, 0.75f, 0.3f}};
    PixelTally full;
    for (const auto& k : c) full.add_corner(k[0], k[1], k[2]);
    const CornerQuad quad = CornerQuad::of(c[0], c[1], c[2], c[3]);
    const CornerQuad spread_only = CornerQuad::of<false>(c[0], c[1], c[2], c[3]);
    CHECK(quad.n == full.n);
    for (int k = 0; k < 3; ++k) {
        CHECK(quad.sum[k] == full.sum[k]);
        CHECK(quad.sum_sq[k] == full.sum_sq[k]);
        CHECK(spread_only.sum_sq[k] == full.sum_sq[k]);
    }
    // Channel variances 0.455625, 0.122292, 0.021406 (worked out by hand), mean 0.199774:
    // standard error sqrt(0.199774 / 4) = 0.22348, so a pixel of 4 samples stops at
    // T (4 / 16)^(3/4) = 0.35355 T for T >= 0.6321.
    CHECK(quad.standard_error() == doctest::Approx(0.22348).epsilon(1e-4));
    CHECK(quad.standard_error() == full.standard_error());
    CHECK(quad.image_error_squared() == full.image_error_squared());
    CHECK(spread_only.scaled_variance() == full.scaled_variance());
    for (const double t : {0.63, 0.64}) {
        const AdaptiveRule rule{t, 64};
        CHECK(rule.above(quad.scaled_variance(), quad.n) == rule.above(full));
    }
    CHECK(AdaptiveRule{0.63, 64}.above(quad.scaled_variance(), quad.n));
    CHECK_FALSE(AdaptiveRule{0.64, 64}.above(quad.scaled_variance(), quad.n));
    // The mean: the corners' colours, (0.9 + 0.25 + 0 + 1.5) / 4 = 0.6625 in red.
    CHECK(quad.mean().x == doctest::Approx(0.6625).epsilon(1e-7));
    CHECK(quad.mean().x == full.mean().x);
    CHECK(quad.mean().y == full.mean().y);
    CHECK(quad.mean().z == full.mean().z);
}

TEST_CASE("adaptive: a pixel's four corners weigh as half a sample of its own in its mean and its estimate") {
    REQUIRE(kCornerWeight == 0.125);
    // Corners of grey 0 (an edge along the pixel's border), then four samples of its own of 1.
    PixelTally t;
    t.begin_round();
    for (int i = 0; i < 4; ++i) t.add_corner(0.f, 0.f, 0.f);
    CHECK(t.mean().x == 0.0);  // corners alone: their mean, whatever their weight
    t.begin_round();
    for (int i = 0; i < 4; ++i) t.add(1.f, 1.f, 1.f);
    CHECK(t.n == 8);
    CHECK(t.corners == 4);
    // Mean (4 x 0.125 x 0 + 4 x 1) / (4 x 0.125 + 4) = 4 / 4.5 = 8/9, not the 0.5 of equal weights.
    CHECK(t.mean().x == doctest::Approx(8.0 / 9.0).epsilon(1e-15));
    CHECK(t.mean().y == doctest::Approx(8.0 / 9.0).epsilon(1e-15));
    // The spread counts every sample alike: 0, 0, 0, 0, 1, 1, 1, 1: s^2 = 8 x 0.25 / 7,
    // standard error sqrt(2/7 / 8) = sqrt(1/28).
    CHECK(t.standard_error() == doctest::Approx(std::sqrt(1.0 / 28.0)).epsilon(1e-12));
    // The image's estimate: before the round A = 0 of weight 0.5, the round B = 1 of 4 samples:
    // (A - B)^2 x 0.5 x 4 / (0.5 + 4)^2 = 2 / 20.25.
    CHECK(t.image_error_squared() == doctest::Approx(2.0 / 20.25).epsilon(1e-12));
    // Round 2, eight samples of 1: before it A = 4 / 4.5 = 8/9 of weight 4.5, so
    // (1/9)^2 x 4.5 x 8 / 12.5^2 = (36 / 81) / 156.25; the mean (4 + 8) / 12.5 = 0.96.
    t.begin_round();
    for (int i = 0; i < 8; ++i) t.add(1.f, 1.f, 1.f);
    CHECK(t.image_error_squared() == doctest::Approx(36.0 / 81.0 / 156.25).epsilon(1e-12));
    CHECK(t.mean().x == doctest::Approx(0.96).epsilon(1e-15));
}

TEST_CASE("adaptive: round 1 follows the pixel's or a neighbour's spread, later rounds its own") {
    const AdaptiveRule rule{0.01, 32};
    PixelTally flat;  // four equal samples: no spread of its own
    for (int i = 0; i < 4; ++i) flat.add(0.5f, 0.5f, 0.5f);
    CHECK(rule.takes_round(PixelTally{}, 0, false));
    CHECK_FALSE(rule.takes_round(flat, 0, false));  // took it already
    CHECK_FALSE(rule.takes_round(flat, 1, false));
    CHECK(rule.takes_round(flat, 1, true));  // a neighbour saw an edge
    PixelTally edge = flat;
    // 8 samples, half black: mean 0.25, s^2 = 8 x 0.0625 / 7, se = sqrt(s^2 / 8) = 0.0945 > T.
    for (int i = 0; i < 4; ++i) edge.add(0.f, 0.f, 0.f);
    CHECK(rule.takes_round(edge, 2, false));
    CHECK_FALSE(rule.takes_round(edge, 3, false));  // round 2 not taken yet
    PixelTally settled = flat;
    for (int i = 0; i < 4; ++i) settled.add(0.5f, 0.5f, 0.5f);
    CHECK_FALSE(rule.takes_round(settled, 2, true));  // the neighbour rule is round 1's only
}

TEST_CASE("adaptive: a pixel of n samples stops at the standard error T (n / 16)^(3/4)") {
    const AdaptiveRule rule{0.01, 64};
    // Two values a and b, half the samples each: se = (|a - b| / 2) / sqrt(n - 1).
    const auto pixel = [](int n, float a, float b) {
        PixelTally t;
        for (int i = 0; i < n; ++i) t.add(i % 2 ? a : b, i % 2 ? a : b, i % 2 ? a : b);
        return t;
    };
    // 4 samples, se = 0.0075 / sqrt(3) = 0.00433: above T (4 / 16)^(3/4) = 0.003536, though
    // under T sqrt(4 / 16) = 0.005 (the square-root rule would stop it).
    const PixelTally few = pixel(4, 0.5075f, 0.4925f);
    CHECK(few.standard_error() == doctest::Approx(0.0075 / std::sqrt(3.0)).epsilon(1e-5));
    CHECK(rule.above(few));
    // 32 samples, se = 0.086 / sqrt(31) = 0.01545: under T (32 / 16)^(3/4) = 0.01682, though
    // over T sqrt(32 / 16) = 0.01414 (the square-root rule would go on).
    const PixelTally many = pixel(32, 0.586f, 0.414f);
    CHECK(many.standard_error() == doctest::Approx(0.086 / std::sqrt(31.0)).epsilon(1e-5));
    CHECK_FALSE(rule.above(many));
    // And just over it: se = 0.0943 / sqrt(31) = 0.01694.
    CHECK(rule.above(pixel(32, 0.5943f, 0.4057f)));
    // 16 samples stop at T itself: half-spreads 1.05 T sqrt(15) and 0.95 T sqrt(15) give
    // se = 1.05 T (above) and 0.95 T (not).
    CHECK(rule.above(pixel(16, float(0.5 + 0.0105 * std::sqrt(15.0)), float(0.5 - 0.0105 * std::sqrt(15.0)))));
    CHECK_FALSE(rule.above(pixel(16, float(0.5 + 0.0095 * std::sqrt(15.0)), float(0.5 - 0.0095 * std::sqrt(15.0)))));
}

TEST_CASE("adaptive: the same picture and sample counts for -j1, -j2 and tile by tile, both engines") {
    const Scene sc = adaptive_scene(0.004);
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(engine));
        const RenderResult one = render(sc, engine, 1), two = render(sc, engine, 2);
        REQUIRE(one.adaptive);
        CHECK(one.image.rgb == two.image.rgb);
        CHECK(one.sample_map.rgb == two.sample_map.rgb);
        CHECK(one.counts.total() == two.counts.total());
        // Tile by tile: each tile alone gives the whole-image render's pixels bit for bit.
        CHECK(render_tile_by_tile(sc, engine).rgb == one.image.rgb);
    }
}

TEST_CASE("adaptive: each tile's rounds run to its end in one go give the round-by-round loop's picture, map and estimate") {
    // With nothing to stop at between rounds, each tile runs its rounds and is finished at once
    // (render_adaptive_image's fused step); a time limit or an image target that is never
    // reached keeps the loop that waits for every tile at the end of each round.
    const Scene sc = adaptive_scene(0.004);
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(engine));
        const RenderResult fused = render(sc, engine, 2);
        for (const AdaptiveStop& stop : {AdaptiveStop{.time_limit = 1e6}, AdaptiveStop{.target_error = 1e-12}}) {
            const RenderResult looped = render(sc, engine, 2, stop);
            REQUIRE(looped.adaptive);
            CHECK(!looped.adaptive->time_limited);
            CHECK(fused.image.rgb == looped.image.rgb);
            CHECK(fused.sample_map.rgb == looped.sample_map.rgb);
            CHECK(fused.adaptive->rounds == looped.adaptive->rounds);
            CHECK(fused.adaptive->mean_spp == looped.adaptive->mean_spp);
            CHECK(fused.adaptive->estimated_rmse == looped.adaptive->estimated_rmse);
            CHECK(fused.counts.total() == looped.counts.total());
        }
    }
}

TEST_CASE("adaptive: tile by tile on a scene with a mesh, the whole image's picture bit for bit") {
    // A corner is traced in one packet by the whole image and in another by a tile alone; a
    // mesh hit that depended on the packet's other rays (the watertight test's double
    // fallback taken for every lane once one lane needed it) changed 78 pixels of this scene
    // by an ulp or two.
    Scene sc = load_scene(std::string(STREAMRT_SOURCE_DIR) + "/scenes/textured.cfg");
    sc.settings.adaptive = 0.03;
    sc.settings.spp = 64;
    const RenderResult whole = render(sc, EngineKind::Stream, 2);
    REQUIRE(whole.adaptive);
    CHECK(render_tile_by_tile(sc, EngineKind::Stream).rgb == whole.image.rgb);
}

TEST_CASE("adaptive: without a sample map asked for, the same picture and no map") {
    const Scene sc = adaptive_scene(0.004);
    const RenderResult with_map = render(sc, EngineKind::Stream, 2);
    EngineOptions options;
    options.sample_map = false;
    Parallelism par(2);
    auto prepared = prepare_render(sc, EngineKind::Stream, options);
    const RenderResult without = render_prepared(*prepared, par);
    REQUIRE(without.adaptive);
    CHECK(without.image.rgb == with_map.image.rgb);
    CHECK(without.adaptive->mean_spp == with_map.adaptive->mean_spp);
    CHECK(without.sample_map.rgb.empty());
    REQUIRE(with_map.sample_map.rgb.size() == with_map.image.rgb.size());
    CHECK(with_map.sample_map.width == sc.settings.width);
}

TEST_CASE("adaptive: counts stay within [4, cap], flat pixels stop at 4, edges reach the cap") {
    const Scene sc = adaptive_scene(1e-9);  // below any spread: every pixel with one goes on
    const RenderResult r = render(sc, EngineKind::Stream, 2);
    const std::size_t n = std::size_t(sc.settings.width * sc.settings.height);
    int at_4 = 0, at_cap = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const float s = samples_at(r, i);
        CHECK((s == 4 || s == 8 || s == 16 || s == 32));
        at_4 += s == 4, at_cap += s == 32;
    }
    // The sky (background, top rows) is flat: pixel (24, 0) takes 4 samples.
    CHECK(samples_at(r, 24) == 4);
    CHECK(at_4 > 0);
    CHECK(at_cap > 0);
    CHECK(r.adaptive->mean_spp > 4);
    CHECK(r.adaptive->mean_spp < 32);
}

TEST_CASE("adaptive: a smaller threshold never gives a pixel fewer samples") {
    const std::size_t n = 48 * 32;
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(engine));
        std::vector<float> before(n, 0.f);
        double mean_before = 0;
        for (double t : {0.05, 0.01, 0.002, 0.0004}) {
            CAPTURE(t);
            const RenderResult r = render(adaptive_scene(t), engine, 2);
            for (std::size_t i = 0; i < n; ++i) CHECK(samples_at(r, i) >= before[i]);
            for (std::size_t i = 0; i < n; ++i) before[i] = samples_at(r, i);
            CHECK(r.adaptive->mean_spp >= mean_before);
            mean_before = r.adaptive->mean_spp;
        }
    }
}

TEST_CASE("adaptive: a spent time limit stops after the first round, an image target stops early") {
    const Scene sc = adaptive_scene(1e-9);
    // 1 ns: spent before the first round ends, which always covers the image.
    const RenderResult timed = render(sc, EngineKind::Stream, 2, AdaptiveStop{.time_limit = 1e-9});
    REQUIRE(timed.adaptive);
    CHECK(timed.adaptive->time_limited);
    CHECK(timed.adaptive->rounds == 1);
    // The first round's corners, (48 + 1) x (32 + 1), each traced once for its pixels.
    CHECK(timed.adaptive->mean_spp == doctest::Approx(49.0 * 33.0 / (48.0 * 32.0)).epsilon(1e-12));
    // A target the first round already meets: the render stops there.
    const RenderResult loose = render(sc, EngineKind::Stream, 2, AdaptiveStop{.target_error = 0.5});
    CHECK(loose.adaptive->rounds == 1);
    CHECK(loose.adaptive->estimated_rmse <= 0.5);
    // A tighter target takes more rounds and reaches it or runs out of rounds (the cap).
    const RenderResult first = render(sc, EngineKind::Stream, 2, AdaptiveStop{.time_limit = 1e-9});
    const double first_rmse = first.adaptive->estimated_rmse;
    const RenderResult tight = render(sc, EngineKind::Stream, 2, AdaptiveStop{.target_error = first_rmse * 0.6});
    CHECK(tight.adaptive->rounds > 1);
    CHECK(tight.adaptive->estimated_rmse < first_rmse);
    CHECK((tight.adaptive->estimated_rmse <= first_rmse * 0.6 || tight.adaptive->rounds == 4));
}

TEST_CASE("adaptive: the image's estimated error is within a factor 1.5 of the error measured against a reference") {
    // The test scene at T = 0.01, cap 32, against 1024 uniform stratified samples per pixel
    // (an error far below the adaptive picture's, 0.017): the RMSE of the
    // luminance, which is what the estimate measures.
    Scene reference_scene = adaptive_scene(0.0, 1024);
    const RenderResult reference = render(reference_scene, EngineKind::Stream, 2);
    const RenderResult adaptive = render(adaptive_scene(0.01), EngineKind::Stream, 2);
    REQUIRE(adaptive.adaptive);
    const auto y = [](const float* p) { return luminance(p[0], p[1], p[2]); };
    double sum = 0;
    const std::size_t n = std::size_t(reference.image.width) * std::size_t(reference.image.height);
    for (std::size_t i = 0; i < n; ++i) {
        const double d = y(&adaptive.image.rgb[i * 3]) - y(&reference.image.rgb[i * 3]);
        sum += d * d;
    }
    const double measured = std::sqrt(sum / double(n));
    const double estimated = adaptive.adaptive->estimated_rmse;
    CAPTURE(measured);
    CAPTURE(estimated);
    CHECK(estimated <= 1.5 * measured);
    CHECK(estimated >= measured / 1.5);
}
