#pragma once
// Where each sample falls inside its pixel. Both engines use these formulas with the same
// (pixel, sample) pair, in float, so they trace the same rays and the picture never depends
// on the thread count or the order of work. The hash is 32-bit integer arithmetic so the
// stream engine's generate kernel computes it in SIMD lanes, bit for bit the same.
#include <cmath>
#include <cstdint>

#include "scene/scene.h"
#include "simd/lanes.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// A 32-bit integer hash with good avalanche (xor-shift-multiply, "lowbias32" constants).
/// U is std::uint32_t or an xsimd batch of it.
template <class U>
inline U hash32(U x) {
    x = x ^ (x >> 16);
    x = x * U(0x7feb352du);
    x = x ^ (x >> 15);
    x = x * U(0x846ca68bu);
    return x ^ (x >> 16);
}

/// The two hashes of sample k of a pixel (its row-major index in the image).
template <class U>
inline void sample_hashes(const U& pixel, const U& k, U& h1, U& h2) {
    h1 = hash32(pixel * U(0x9e3779b1u) + k * U(0x85ebca77u) + U(1u));
    h2 = hash32(h1 ^ U(0x5bd1e995u));
}

/// Top 24 bits of a hash as a float in [0, 1), exactly representable. U is std::uint32_t
/// (giving float) or a batch of it (giving a float batch).
template <class U>
inline auto unit_from_hash(const U& h) {
    const auto f = simd::to_float(h >> 8);
    return f * decltype(f)(0x1p-24f);
}

template <class V>
struct PixelSampleT {
    V x, y;  ///< offset inside the pixel, in [0, 1)
};
using PixelSample = PixelSampleT<float>;

/// Lattice used by the grid and stratified patterns: cols x rows = spp exactly, as square
/// as possible (cols is the smallest divisor of spp not below its square root).
inline int grid_columns(int spp) {
    int cols = int(std::ceil(std::sqrt(double(spp))));
    while (spp % cols != 0) ++cols;
    return cols;
}

/// Offset of a sample in its lattice cell (cx, cy) of a cols x rows lattice, from the two
/// hash values u, v in [0, 1): grid takes cell centres, stratified one uniform point per
/// cell, random ignores the lattice. V is float, or a float batch in the generate kernel.
template <class V>
inline PixelSampleT<V> lattice_sample(SamplePattern pattern, const V& cx, const V& cy, const V& cols, const V& rows,
                                      const V& u, const V& v) {
    if (pattern == SamplePattern::Random) return {u, v};
    const V ju = pattern == SamplePattern::Grid ? V(0.5f) : u;
    const V jv = pattern == SamplePattern::Grid ? V(0.5f) : v;
    return {(cx + ju) / cols, (cy + jv) / rows};
}

/// Sample `sample` of `spp` in pixel `pixel` (row-major index). spp = 1 always takes the
/// pixel centre.
inline PixelSample pixel_sample(SamplePattern pattern, int spp, std::uint64_t pixel, int sample) {
    if (spp == 1) return {0.5f, 0.5f};
    std::uint32_t h1, h2;
    sample_hashes(std::uint32_t(pixel), std::uint32_t(sample), h1, h2);
    const int cols = grid_columns(spp);
    return lattice_sample(pattern, float(sample % cols), float(sample / cols), float(cols), float(spp / cols),
                          unit_from_hash(h1), unit_from_hash(h2));
}

// ---- Area lights (docs/scene-format.md, "Area lights and soft shadows") ----------------

/// The key of camera sample k of a pixel (row-major index) for light sampling. Every ray a
/// camera sample spawns (reflected, refracted) carries it, so a pixel's light samples are
/// the same for every thread count and in both engines.
inline std::uint32_t light_key(std::uint64_t pixel, int sample) {
    return hash32(std::uint32_t(pixel) * 0x27d4eb2fu + std::uint32_t(sample) * 0x165667b1u + 0x3c6ef372u);
}

/// The two hashes of light sample j of light `light` for a ray of key `key` (U: uint32 or a
/// batch of it, one key per lane).
template <class U>
inline void light_sample_hashes(const U& key, std::uint32_t light, std::uint32_t j, U& h1, U& h2) {
    h1 = hash32(key ^ U(hash32(light * 0x85ebca77u + j * 0xc2b2ae3du + 0x9e3779b9u)));
    h2 = hash32(h1 ^ U(0x5bd1e995u));
}

STREAMRT_ISA_END
}  // namespace streamrt
