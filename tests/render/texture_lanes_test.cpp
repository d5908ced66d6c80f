// Texture lookups on xsimd batches (render/texture.h, what the SIMD shade kernel runs): each
// lane gets the scalar float lookup's bits, whatever mip levels the lanes of one batch need;
// and the hand-worked bilinear value of texture_test.cpp in every lane.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "render/texture.h"
#include "simd/lanes_test_util.h"

using namespace streamrt;

namespace {

using B = xsimd::batch<float>;
constexpr std::size_t W = B::size;

// An independent trilinear lookup in double, written from docs/scene-format.md ("Textures and
// UV mapping") and not from render/texture.h: texel (i, j) is centred at
// ((i + 0.5) / width, 1 - (j + 0.5) / height), the image repeats, the level is log2 of the
// footprint in finest-level texels, clamped to [0, coarsest], and two levels mix linearly.
double ref_texel(const TextureLevelView& l, long i, long j, int c) {
    const long w = l.width, h = l.height;
    i = ((i % w) + w) % w;
    j = ((j % h) + h) % h;
    return double(l.rgb[(std::size_t(j) * std::size_t(w) + std::size_t(i)) * 3 + std::size_t(c)]);
}
double ref_bilinear(const TextureLevelView& l, double u, double v, int c) {
    const double x = u * l.width - 0.5, y = (1.0 - v) * l.height - 0.5;  // repeat: any u, v
    const double fx = std::floor(x), fy = std::floor(y), ax = x - fx, ay = y - fy;
    const long i = long(fx), j = long(fy);
    return (1 - ay) * ((1 - ax) * ref_texel(l, i, j, c) + ax * ref_texel(l, i + 1, j, c)) +
           ay * ((1 - ax) * ref_texel(l, i, j + 1, c) + ax * ref_texel(l, i + 1, j + 1, c));
}
double ref_trilinear(const TextureView& t, double u, double v, double texels, int c) {
    const double lod = std::min(texels > 1 ? std::log2(texels) : 0.0, double(t.count - 1));
    const int i = int(std::floor(lod));
    const double f = lod - i;
    const double c0 = ref_bilinear(t.levels[i], u, v, c);
    return i + 1 < t.count ? (1 - f) * c0 + f * ref_bilinear(t.levels[i + 1], u, v, c) : c0;
}

}  // namespace

// Proven against: the batch level loop stopping before the highest level a lane needs (lanes
// mixing in the next level read black); i and j swapped in the gathered offsets; v not
// flipped (1 - v dropped in texture_bilinear: scalar and batch agree, the reference does not);
// the mix weight f and 1 - f swapped in texture_sample (likewise).
TEST_CASE("texture lanes: a batch lookup is the scalar float lookup in every lane, and the reference lookup") {
    // 7 x 5 (odd sides: levels 7x5, 3x2, 1x1), texel values from a fixed pattern.
    std::vector<float> rgb(7 * 5 * 3);
    for (std::size_t k = 0; k < rgb.size(); ++k) rgb[k] = float((k * 37) % 101) / 100.f;
    const auto t = Texture::build("odd", 7, 5, rgb);
    const TextureView view = t->view();
    REQUIRE(view.count == 3);
    test::Lcg gen;
    const auto next = [&] { return float(gen.next()); };
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    for (int k = 0; k < 4000; ++k) {
        alignas(64) float u[W], v[W], texels[W], r[W], g[W], b[W];
        for (std::size_t l = 0; l < W; ++l) {
            u[l] = 6.f * next() - 3.f;
            v[l] = 6.f * next() - 3.f;
            texels[l] = std::exp2(6.f * next() - 2.f);  // levels 0 to 2, blends between them
        }
        if (k % 7 == 0) u[k % W] = nan;  // a NaN or inf lane, as padding lanes may hold
        if (k % 11 == 0) texels[(k + 1) % W] = k % 2 ? inf : nan;
        const ColorT<B> c = texture_sample(view, B::load_aligned(u), B::load_aligned(v), B::load_aligned(texels));
        c.x.store_aligned(r);
        c.y.store_aligned(g);
        c.z.store_aligned(b);
        for (std::size_t l = 0; l < W; ++l) {
            const ColorT<float> s = texture_sample(view, u[l], v[l], texels[l]);
            CHECK(test::float_bits(r[l]) == test::float_bits(s.x));
            CHECK(test::float_bits(g[l]) == test::float_bits(s.y));
            CHECK(test::float_bits(b[l]) == test::float_bits(s.z));
            if (!std::isfinite(u[l]) || !std::isfinite(texels[l])) continue;  // any texel: no reference
            // The lookup is continuous in u, v and the level, so float rounding of the texel
            // position (|u| <= 3: 2^-22 of a unit, times 7 texels) and of log2 (1.1e-9) moves
            // the value by far less than 1e-5 of the texel range [0, 1].
            CAPTURE(k); CAPTURE(l); CAPTURE(u[l]); CAPTURE(v[l]); CAPTURE(texels[l]);
            CHECK(r[l] == doctest::Approx(ref_trilinear(view, u[l], v[l], texels[l], 0)).epsilon(1e-5));
            CHECK(g[l] == doctest::Approx(ref_trilinear(view, u[l], v[l], texels[l], 1)).epsilon(1e-5));
            CHECK(b[l] == doctest::Approx(ref_trilinear(view, u[l], v[l], texels[l], 2)).epsilon(1e-5));
        }
    }
}

// Proven against: i and j swapped in the gathered offsets (3/4 red + 1/4 blue).
TEST_CASE("texture lanes: the hand-worked bilinear value in every lane") {
    // The 2 x 2 texture: top row red, green; bottom row blue, white. At (0.375, 0.75):
    // x = 0.375 x 2 - 0.5 = 0.25 on the top row: 3/4 red + 1/4 green.
    const auto q = Texture::build("quad", 2, 2, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1});
    const ColorT<B> c = texture_bilinear(q->levels[0], B(0.375f), B(0.75f));
    alignas(64) float r[W], g[W], b[W];
    c.x.store_aligned(r);
    c.y.store_aligned(g);
    c.z.store_aligned(b);
    for (std::size_t l = 0; l < W; ++l) {
        CHECK(r[l] == doctest::Approx(0.75));
        CHECK(g[l] == doctest::Approx(0.25));
        CHECK(b[l] == doctest::Approx(0.0));
    }
}
