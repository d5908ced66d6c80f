#pragma once
// Which camera samples a tile render traces, and where their light goes.
#include <cstddef>
#include <cstdint>

#include "parallel/parallelism.h"
#include "render/sampling.h"

namespace streamrt {

/// A run of samples (render/sampling.h's SampleRun) for some pixels of a tile.
/// Uniform sampling: every pixel of the tile, the run {0, spp}, each pixel's samples summed
/// into the pixel's slot with weight 1/spp. Adaptive sampling (render/adaptive.h): a round's
/// run for a list of pixels, each sample into a slot of its own with weight 1, so the driver
/// sees every sample's colour (its spread is the pixel's error estimate).
struct SampleRequest {
    SampleRun run;
    const std::uint32_t* pixels = nullptr;  ///< tile-local pixel numbers (row by row); null: all
    int n_pixels = 0;                       ///< pixels listed (or the tile's, when null)
    bool per_sample = false;

    int pixel(int i) const { return pixels ? int(pixels[i]) : i; }
    /// The slot of sample j of listed pixel i, counted from the chunk's first pixel (per
    /// sample), or the tile-local pixel p (summed).
    std::int32_t slot_of(int i_in_chunk, int j, int p) const {
        return per_sample ? std::int32_t(i_in_chunk * run.count + j) : std::int32_t(p);
    }
    /// The samples one slot sums: the run's for uniform sampling, 1 for adaptive sampling's
    /// own slots. A ray's weight is its reciprocal, and the cut-off is scaled by it.
    int samples_per_slot() const { return per_sample ? 1 : run.count; }
    float weight() const { return 1.f / float(samples_per_slot()); }
    /// Slots a chunk of n listed pixels accumulates into.
    std::size_t slots(int n, const Tile& tile) const {
        return per_sample ? std::size_t(n) * std::size_t(run.count) : std::size_t(tile.width() * tile.height());
    }
};

}  // namespace streamrt
