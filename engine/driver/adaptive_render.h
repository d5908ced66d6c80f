#pragma once
// Adaptive sampling's driver (docs/adaptive-sampling.md): runs render/adaptive.h's rounds on
// an engine's render_samples, a tile at a time or across the whole image. Each round is a
// stream of the pixels that still need samples; the engines keep their own shape.
#include <cstdint>
#include <vector>

#include "driver/render.h"

namespace streamrt {

/// The tallies of the pixels of a rectangle that take samples after the corner round (every
/// pixel without one), in row order: most pixels of a picture stop at their corners, and
/// their values are read from the corners themselves (120 bytes a pixel only where needed).
struct TileTallies {
    Tile tile{};
    std::vector<PixelTally> tallies;
    std::vector<std::uint32_t> pixel;  ///< each tally's pixel in the rectangle (row by row), ascending
    /// Each tally's AdaptiveRule::takes_round spread_near: its error after round 0, or one of
    /// its neighbours', above its stopping point.
    std::vector<std::uint8_t> spread_near;
    std::vector<std::uint32_t> took_last;  ///< the tallies that took the last round run on the tile
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
