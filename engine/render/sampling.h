#pragma once
// Where each sample falls inside its pixel. Both engines call this with the same
// (pixel, sample) pair, so they trace the same rays and the picture never depends on the
// thread count or the order of work.
#include <cmath>
#include <cstdint>

#include "scene/scene.h"

namespace streamrt {

/// splitmix64's finaliser: a good 64-bit mix of a counter.
inline std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/// A uniform double in [0, 1) from 53 bits of a hash.
inline double unit_from_bits(std::uint64_t bits) { return double(bits >> 11) * 0x1.0p-53; }

struct PixelSample {
    double x, y;  ///< offset inside the pixel, in [0, 1)
};

/// Lattice used by the grid and stratified patterns: cols x rows = spp exactly, as square
/// as possible (cols is the smallest divisor of spp not below its square root).
inline int grid_columns(int spp) {
    int cols = int(std::ceil(std::sqrt(double(spp))));
    while (spp % cols != 0) ++cols;
    return cols;
}

/// Sample `sample` of `spp` in pixel `pixel` (row-major index). spp = 1 always takes the
/// pixel centre. grid: cell centres; stratified: one jittered point per cell; random:
/// independent uniform points.
inline PixelSample pixel_sample(SamplePattern pattern, int spp, std::uint64_t pixel, int sample) {
    if (spp == 1) return {0.5, 0.5};
    const std::uint64_t h = mix64(pixel * 0x9e3779b97f4a7c15ull + std::uint64_t(sample) + 1);
    const double u = unit_from_bits(h), v = unit_from_bits(mix64(h));
    if (pattern == SamplePattern::Random) return {u, v};
    const int cols = grid_columns(spp);
    const int rows = spp / cols;
    const int cx = sample % cols, cy = sample / cols;
    const double jx = pattern == SamplePattern::Grid ? 0.5 : u;
    const double jy = pattern == SamplePattern::Grid ? 0.5 : v;
    return {(cx + jx) / cols, (cy + jy) / rows};
}

}  // namespace streamrt
