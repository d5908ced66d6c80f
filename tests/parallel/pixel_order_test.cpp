// The Z order of a tile's pixels (parallel/pixel_order.h).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "parallel/pixel_order.h"

using namespace streamrt;

TEST_CASE("pixel order: a whole tile's pixels in Z order come in square blocks") {
    REQUIRE(kTileSize == 16);
    std::uint32_t order[kTileSize * kTileSize];
    REQUIRE(z_order_pixels(Tile{32, 48, 48, 64}, order) == 256);
    // The first 16: the 4 x 4 block at the top left, itself in 2 x 2 blocks (worked by hand:
    // pixel y * 16 + x).
    const std::uint32_t first16[16] = {0, 1, 16, 17, 2, 3, 18, 19, 32, 33, 48, 49, 34, 35, 50, 51};
    for (int i = 0; i < 16; ++i) CHECK(order[i] == first16[i]);
    // Pixels 16 - 31 are the 4 x 4 block to its right (x 4 - 7, y 0 - 3), 32 - 47 the one below.
    CHECK(order[16] == 4);
    CHECK(order[31] == 3 * 16 + 7);
    CHECK(order[32] == 4 * 16 + 0);
    CHECK(order[255] == 255);
    // Every group of 16 consecutive pixels spans 4 columns and 4 rows.
    for (int g = 0; g < 16; ++g) {
        std::uint32_t x_lo = 99, x_hi = 0, y_lo = 99, y_hi = 0;
        for (int i = g * 16; i < g * 16 + 16; ++i) {
            x_lo = std::min(x_lo, order[i] % 16), x_hi = std::max(x_hi, order[i] % 16);
            y_lo = std::min(y_lo, order[i] / 16), y_hi = std::max(y_hi, order[i] / 16);
        }
        CHECK(x_hi - x_lo == 3);
        CHECK(y_hi - y_lo == 3);
    }
}

TEST_CASE("pixel order: a partial tile lists each of its pixels once, numbered by its own width") {
    // A tile of 5 x 3 at the image's corner: numbers y * 5 + x.
    std::uint32_t order[kTileSize * kTileSize];
    const int n = z_order_pixels(Tile{640, 480, 645, 483}, order);
    REQUIRE(n == 15);
    std::vector<std::uint32_t> seen(order, order + n);
    std::sort(seen.begin(), seen.end());
    for (int i = 0; i < 15; ++i) CHECK(seen[std::size_t(i)] == std::uint32_t(i));
    // Z order skips what lies outside: (0,0) (1,0) (0,1) (1,1), then (2,0) (3,0) (2,1) (3,1).
    const std::uint32_t first8[8] = {0, 1, 5, 6, 2, 3, 7, 8};
    for (int i = 0; i < 8; ++i) CHECK(order[i] == first8[i]);
}
