#pragma once
// Where each sample falls inside its pixel. Both engines use these formulas with the same
// (pixel, sample) pair, in float, so they trace the same rays and the picture never depends
// on the thread count or the order of work. The hash is 32-bit integer arithmetic so the
// stream engine's generate kernel computes it in SIMD lanes, bit for bit the same.
#include <cmath>
#include <cstdint>

#include "scene/scene.h"
#include "simd/lanes.h"
#include "simd/stable_math.h"
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

/// A run of one pixel's samples: numbers [first, first + count), stratified among
/// themselves on their own cols x rows lattice (grid_columns(count)). Uniform sampling is
/// the one run {0, spp}. The sample number (first + j) seeds the hashes, so no two samples
/// of a pixel share their jitter.
/// Adaptive sampling (render/adaptive.h) takes its rounds as runs of the pixel's own
/// sequence (`sequence`): with the stratified pattern, sample k is point k of a scrambled
/// (0,2)-sequence (sequence_sample), so every round and every union of rounds covers the
/// pixel evenly, not only each round alone.
struct SampleRun {
    int first = 0;
    int count = 1;
    bool sequence = false;
    /// A pixel-corner sample (adaptive sampling's first round, corner_run()): the one sample
    /// at offset (0, 0) of "pixel" (x, y), x in [0, width] and y in [0, height], the corner
    /// that up to four pixels share. Its hash key is the corner's own number (sample_key),
    /// so it is the same sample whichever render of which neighbour takes it.
    bool corner = false;
};

/// The sample number of a corner sample: apart from any pixel's own sample numbers (at most
/// the largest spp), so its lens point and light samples have hashes of their own.
inline constexpr int kCornerSampleNumber = 1 << 30;
inline constexpr SampleRun corner_run() { return {.first = kCornerSampleNumber, .count = 1, .corner = true}; }

/// The hash key of pixel (x, y) of a `width`-pixel-wide image (its row-major index), or for
/// a corner run the corner's row-major index on the (width + 1)-wide lattice of corners.
inline std::uint32_t sample_key(SampleRun run, int x, int y, int width) {
    const std::uint64_t row = std::uint64_t(width) + (run.corner ? 1u : 0u);
    return std::uint32_t(std::uint64_t(y) * row + std::uint64_t(x));
}

// ---- adaptive rounds: a scrambled (0,2)-sequence per pixel --------------------------------
// Points [0, 2^m) of Sobol's first two dimensions, and every aligned block [j 2^m,
// (j + 1) 2^m) of them, hold one point in each elementary interval of area 2^-m (each
// 2^a x 2^(m-a) box of the pixel): a (0,2)-sequence. Adaptive rounds double what a pixel
// holds (samples [4, 8), [8, 16), [16, 32), ...), so every round is such a block and the
// samples a pixel holds after any round are the sequence's first 2^m points less the four
// it skipped for the corners: stratified as a whole. Rounds stratified each on their own
// lattice are not, and measured so on an edge pixel of 60 samples the union of four rounds
// has 1.6x the error of the sequence's [4, 64) (docs/adaptive-sampling.md).
// Each pixel scrambles the sequence with its own seed: a hash that changes digit k of a
// coordinate by the digits above it only (Owen's nested scrambling, in the hashed form of
// Laine and Karras 2011 as tuned by Burley 2020), which keeps every elementary interval
// full and makes the points of neighbouring pixels unrelated.

/// The bits of x in reverse order. U is std::uint32_t or an xsimd batch of it (the generate
/// kernel runs these in SIMD lanes, bit for bit the same).
template <class U>
inline U reverse_bits(U x) {
    x = (x << 16) | (x >> 16);
    x = ((x & U(0x00ff00ffu)) << 8) | ((x >> 8) & U(0x00ff00ffu));
    x = ((x & U(0x0f0f0f0fu)) << 4) | ((x >> 4) & U(0x0f0f0f0fu));
    x = ((x & U(0x33333333u)) << 2) | ((x >> 2) & U(0x33333333u));
    return ((x & U(0x55555555u)) << 1) | ((x >> 1) & U(0x55555555u));
}

/// A permutation of 32-bit words in which bit k of the result depends on bits 0..k of x
/// only (additions and multiplications by even constants carry upwards only). Applied to a
/// coordinate's reversed bits it is a nested scramble: each digit after the binary point is
/// flipped according to the digits before it.
template <class U>
inline U nested_scramble_reversed(U x, const U& seed) {
    x = x + seed;
    x = x ^ (x * U(0x6c50b47cu));
    x = x ^ (x * U(0xb82f1e52u));
    x = x ^ (x * U(0xc7afe638u));
    x = x ^ (x * U(0x8d22f6e6u));
    return x;
}

/// Sobol's second dimension of point i, as a 32-bit fraction: the generator matrix is
/// Pascal's triangle mod 2, column k being the direction number v_k = v_(k-1) ^ (v_(k-1) >> 1).
/// Without branches on the bits of i, so lanes of different indices run together.
template <class U>
inline U sobol_second_dimension(U i) {
    U y(0u);
    std::uint32_t v = 1u << 31;
    for (int k = 0; k < 32; ++k, v ^= v >> 1) {
        y = y ^ (U(v) & (U(0u) - (i & U(1u))));  // v where bit k of i is set
        i = i >> 1;
        if (simd::none_set(i)) break;  // every lane's higher bits are 0
    }
    return y;
}

/// Point `index` of pixel `pixel`'s (row-major index) scrambled (0,2)-sequence: an offset in
/// [0, 1)^2 with 24 significant bits, as unit_from_hash.
template <class U>
inline auto sequence_sample(const U& pixel, const U& index) {
    const U seed_x = hash32(pixel * U(0x2545f491u) + U(0x9e3779b9u));
    const U seed_y = hash32(seed_x ^ U(0x6a09e667u));
    // The first dimension is the radical inverse of the index: its reversed bits are the index.
    const U x = reverse_bits(nested_scramble_reversed(index, seed_x));
    const U y = reverse_bits(nested_scramble_reversed(reverse_bits(sobol_second_dimension(index)), seed_y));
    return PixelSampleT<decltype(unit_from_hash(x))>{unit_from_hash(x), unit_from_hash(y)};
}

/// Whether sample j of `run` comes from the pixel's sequence (sequence_sample) rather than a
/// lattice: adaptive rounds with the stratified pattern.
inline bool uses_sequence(SamplePattern pattern, SampleRun run) {
    return run.sequence && !run.corner && pattern == SamplePattern::Stratified;
}

/// Sample j (in [0, run.count)) of `run` in pixel `pixel` (row-major index). The run {0, 1}
/// (spp = 1) takes the pixel centre.
inline PixelSample pixel_sample(SamplePattern pattern, SampleRun run, std::uint64_t pixel, int j) {
    if (run.corner) return {0.f, 0.f};
    if (run.first == 0 && run.count == 1) return {0.5f, 0.5f};
    if (uses_sequence(pattern, run)) return sequence_sample(std::uint32_t(pixel), std::uint32_t(run.first + j));
    std::uint32_t h1, h2;
    sample_hashes(std::uint32_t(pixel), std::uint32_t(run.first + j), h1, h2);
    const int cols = grid_columns(run.count);
    return lattice_sample(pattern, float(j % cols), float(j / cols), float(cols), float(run.count / cols),
                          unit_from_hash(h1), unit_from_hash(h2));
}

/// Sample `sample` of `spp` in pixel `pixel`: uniform sampling, the run {0, spp}.
inline PixelSample pixel_sample(SamplePattern pattern, int spp, std::uint64_t pixel, int sample) {
    return pixel_sample(pattern, SampleRun{0, spp}, pixel, sample);
}

// ---- depth of field: where each sample falls on the lens ----------------------------------
// A thin lens needs a second 2-D sample per ray, a point on the lens disc. It uses the same
// cols x rows lattice as the pixel sample, but sample k takes lattice cell permute(k) on the
// lens, with a permutation of [0, spp) drawn per pixel: each 2-D projection (pixel jitter,
// lens point) is stratified, and the pairing of pixel strata with lens strata is a random
// shuffle per pixel (no correlation such as "left of the pixel = left of the lens"). The
// cell index is integer bookkeeping, computed by the scalar driver in both engines; the
// hashes, jitter and disc mapping run in SIMD lanes in the stream engine's generate kernel.

/// The lens cells of one pixel's samples: a bijection of [0, spp) chosen by a hash of the
/// pixel, an invertible mix of the bits of [0, 2^b) (2^b the next power of two >= spp)
/// repeated until the value lands below spp (cycle walking, so the restriction to [0, spp)
/// is still a bijection). Set up once per pixel; cell(k) per sample.
class LensCells {
  public:
    LensCells(int spp, std::uint32_t pixel)
        : n_(std::uint32_t(spp)), cols_(grid_columns(spp)) {
        const std::uint32_t seed = pixel * 0x27d4eb2du + 0x165667b1u;
        mul_ = hash32(seed) | 1u;  // odd: invertible modulo 2^b
        add_ = hash32(seed ^ 0xa511e9b3u);
        mask_ = n_ - 1;
        for (int sh = 1; sh < 32; sh *= 2) mask_ |= mask_ >> sh;
    }
    /// The index in [0, spp) that sample k takes.
    std::uint32_t index(std::uint32_t i) const {
        if (n_ <= 1) return 0;
        do {
            i = (i * mul_ + add_) & mask_;
            i ^= i >> 1;  // xor with a right shift: invertible, stays below 2^b
            i = (i * 0x2c1b3c6du) & mask_;
            i ^= i >> 3;
        } while (i >= n_);
        return i;
    }
    /// Lattice cell (column, row) on the lens of sample k.
    void cell(int k, int& cx, int& cy) const {
        const int j = int(index(std::uint32_t(k)));
        cx = j % cols_;
        cy = j / cols_;
    }

  private:
    std::uint32_t n_;
    int cols_;
    std::uint32_t mul_ = 0, add_ = 0, mask_ = 0;
};

/// The two lens hashes of sample k of a pixel (independent of sample_hashes').
template <class U>
inline void lens_hashes(const U& pixel, const U& k, U& h1, U& h2) {
    h1 = hash32(pixel * U(0x68e31da4u) + k * U(0xb5297a4du) + U(0x1b56c4e9u));
    h2 = hash32(h1 ^ U(0x1b873593u));
}


/// Shirley and Chiu's concentric map of the unit square onto the unit disc: area-preserving
/// (uniform points stay uniform) and it keeps strata compact, unlike the polar map
/// (r = sqrt(u), angle 2 pi v). V is float or a float batch.
template <class V>
inline PixelSampleT<V> concentric_disc(const V& u, const V& v) {
    using namespace simd;
    const V a = V(2.f) * u - V(1.f), b = V(2.f) * v - V(1.f);
    const auto wide = abs(a) > abs(b);  // the wedges around +-x; otherwise those around +-y
    const V r = select(wide, a, b);
    const V num = select(wide, b, a);
    const V den = select(r == V(0.f), V(1.f), r);  // the centre (a = b = 0): r = 0 anyway
    V s, c;
    simd::sin_cos_quarter(V(0.785398163397448f) * (num / den), s, c);
    return {r * select(wide, c, s), r * select(wide, s, c)};
}

/// The point on the unit lens disc of sample `sample` of `spp` in pixel `pixel` (row-major
/// index): the lattice of pixel_sample with the permuted cell of LensCells, so grid puts
/// lens points at cell centres, stratified one per cell, random anywhere. Sample j of a run
/// (SampleRun) takes the run's own lattice and permutation.
inline PixelSample lens_sample(SamplePattern pattern, SampleRun run, std::uint64_t pixel, int j) {
    std::uint32_t h1, h2;
    lens_hashes(std::uint32_t(pixel), std::uint32_t(run.first + j), h1, h2);
    const int cols = grid_columns(run.count);
    int cx, cy;
    LensCells(run.count, std::uint32_t(pixel)).cell(j, cx, cy);
    const PixelSample q = lattice_sample(pattern, float(cx), float(cy), float(cols), float(run.count / cols),
                                         unit_from_hash(h1), unit_from_hash(h2));
    return concentric_disc(q.x, q.y);
}
inline PixelSample lens_sample(SamplePattern pattern, int spp, std::uint64_t pixel, int sample) {
    return lens_sample(pattern, SampleRun{0, spp}, pixel, sample);
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

// ---- Degree 6: the numbers of a path ------------------------------------------------------
// A path's vertices draw from its ray's key. At degree 6 every child takes a key of its own,
// made from its parent's and its kind (child_key), so the numbers depend on (pixel, sample,
// the path's choices so far, dimension) only: both engines and every thread count draw the
// same ones. Below degree 6 children inherit their parent's key, as before.

/// The bits a camera sample's number takes in a degree-6 camera key: enough for [0, spp).
inline int path_sample_bits(int spp) {
    int bits = 0;
    while (bits < 31 && (1u << bits) < std::uint32_t(spp)) ++bits;
    return bits;
}

/// The key of camera sample `sample` (of at most `spp`) of pixel `pixel` (row-major index):
/// below degree 6, light_key; at degree 6 the path's number, pixel << path_sample_bits(spp) |
/// sample (modulo 2^32), from which the first bounce reads the pixel and the sample back
/// (first_bounce_point). Every use of a key hashes it first, so numbered keys serve the light
/// samples and the child keys as well as hashed ones, and distinct paths get distinct keys
/// while pixel x spp stays under 2^32. A sample number that does not fit (adaptive sampling's
/// pixel corners, kCornerSampleNumber) keeps light_key: numbered, a corner would share its key,
/// hence its every number, with sample 0 of the pixel of the same index.
inline std::uint32_t camera_key(int degree, int spp, std::uint64_t pixel, int sample) {
    const int bits = path_sample_bits(spp);
    if (degree < 6 || (std::uint32_t(sample) >> bits) != 0) return light_key(pixel, sample);
    return (std::uint32_t(pixel) << bits) | std::uint32_t(sample);
}

/// The first bounce's two numbers for a camera ray of degree-6 key `key`: point (sample) of
/// the pixel's own scrambled (0,2)-sequence (sequence_sample, scrambled apart from the
/// camera's), so the first bounces of a pixel's samples cover the hemisphere evenly, as its
/// camera rays cover the pixel. Deeper bounces draw hashed numbers.
template <class U>
inline auto first_bounce_point(const U& key, int bits) {
    const U pixel = key >> bits;
    const U sample = key & U((1u << bits) - 1u);
    return sequence_sample(hash32(pixel ^ U(0x68bc21ebu)), sample);
}

/// The key of a ray spawned at degree 6 by a ray of key `key`; `kind` is its RayKind.
template <class U>
inline U child_key(const U& key, std::uint32_t kind) {
    return hash32(key * U(0x9e3779b1u) + U(kind * 0x85ebca77u + 0x27d4eb2fu));
}

/// The three numbers of a diffuse bounce at a hit of a ray of key `key`: the direction's two
/// (cosine_direction) and Russian roulette's. Apart from light_sample_hashes' by their seeds.
template <class U>
inline void bounce_hashes(const U& key, U& h1, U& h2, U& h3) {
    h1 = hash32(key ^ U(0x6b43a9b5u));
    h2 = hash32(h1 ^ U(0x5bd1e995u));
    h3 = hash32(h2 ^ U(0x2c1b3c6du));
}

STREAMRT_ISA_END
}  // namespace streamrt
