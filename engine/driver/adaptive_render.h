#pragma once
// Adaptive sampling's driver (docs/adaptive-sampling.md): runs render/adaptive.h's rounds on
// an engine's render_samples, a tile at a time or across the whole image. Each round is a
// stream of the pixels that still need samples; the engines keep their own shape.
#include <cstdint>
#include <vector>

#include "driver/render.h"

namespace streamrt {

/// One tile's pixels' tallies, row by row.
struct TileTallies {
    Tile tile{};
    std::vector<PixelTally> pixels;
};

/// Runs round r on the pixels of `t` that take it (AdaptiveRule::takes_round); returns how
/// many did. `counts` gets the rays traced.
int refine_tile(PreparedRender& prepared, int r, TileTallies& t, RayCounts& counts, const RenderProgress* cancel);

/// Writes the tile's pixel means into rgb (tile.width() x tile.height() x 3 floats).
void write_means(const TileTallies& t, float* rgb);

/// Every round on one tile, then its means into rgb: the values an adaptive render() gives
/// those pixels when nothing stops it early (PreparedRender::render_tile).
void render_adaptive_tile(PreparedRender& prepared, const Tile& tile, float* rgb, RayCounts& counts,
                          const RenderProgress* cancel);

/// The whole image, round after round across it, until no pixel takes the next round, or
/// prepared.stop says so. Sets prepared.last_adaptive and prepared.sample_map.
Framebuffer render_adaptive_image(PreparedRender& prepared, Parallelism& par, RenderProgress* progress);

}  // namespace streamrt
