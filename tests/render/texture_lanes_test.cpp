// Texture lookups on xsimd batches (render/texture.h, what the SIMD shade kernel runs): each
// lane gets the scalar float lookup's bits, whatever mip levels the lanes of one batch need;
// and the hand-worked bilinear value of texture_test.cpp in every lane.
#include <doctest/doctest.h>

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

}  // namespace

// Proven against: the batch level loop stopping before the highest level a lane needs (lanes
// mixing in the next level read black); i and j swapped in the gathered offsets.
TEST_CASE("texture lanes: a batch lookup is the scalar float lookup in every lane") {
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
