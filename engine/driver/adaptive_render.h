#pragma once
// Adaptive sampling's driver (docs/adaptive-sampling.md): runs render/adaptive.h's rounds on
// an engine's render_samples, a tile at a time or across the whole image. Each round is a
// stream of the pixels that still need samples; the engines keep their own shape.
#include <cstdint>
#include <vector>

#include "driver/render.h"

namespace streamrt {

/// The tallies of a rectangle's pixels, row by row, and (after round 0) whether each has an
/// error above its stopping point (AdaptiveRule::above) in itself or a neighbour
/// (AdaptiveRule::takes_round's spread_near).
struct TileTallies {
    Tile tile{};
    std::vector<PixelTally> pixels;
    std::vector<std::uint8_t> spread_near;
    std::vector<std::uint32_t> took_last;  ///< the pixels that took the last round run on the tile
};

/// Every round on one tile, then its means into rgb (tile.width() x tile.height() x 3):
/// the values an adaptive render() gives those pixels when nothing stops it early
/// (PreparedRender::render_tile). Round 0 also covers the ring of pixels around the tile, for
/// the neighbour rule.
void render_adaptive_tile(PreparedRender& prepared, const Tile& tile, float* rgb, RayCounts& counts,
                          const RenderProgress* cancel);

/// The whole image, round after round across it, until no pixel takes the next round, or
/// prepared.stop says so. Sets prepared.last_adaptive and prepared.sample_map.
Framebuffer render_adaptive_image(PreparedRender& prepared, Parallelism& par, RenderProgress* progress);

}  // namespace streamrt
