#pragma once
// Stream compaction for the kernels: write the active lanes of a batch contiguously. xsimd
// 8.1 has no compress, so AVX-512 uses its compress instruction, AVX2 a permutation table,
// and the other levels a scalar loop. Each form stores a whole register at dst (the streams
// keep kMaxLanes of slack past their capacity for it) and returns how many lanes were active.
// Included only by kernels/isa_*.cpp, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#if defined(__AVX2__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// Which lanes are active, as bits.
template <class A>
inline unsigned lane_bits(const xsimd::batch_bool<float, A>& m) {
    alignas(64) bool b[xsimd::batch<float, A>::size];
    m.store_aligned(b);
    unsigned bits = 0;
    for (std::size_t l = 0; l < xsimd::batch<float, A>::size; ++l) bits |= unsigned(b[l]) << l;
    return bits;
}

/// src[index[l]] in lane l. xsimd 8.1's gather takes a generic element-by-element path for
/// float on AVX-512 and AVX2; these levels get their gather instructions here.
template <class A>
inline xsimd::batch<float, A> gather_floats(const float* src, const xsimd::batch<std::int32_t, A>& index) {
    constexpr std::size_t W = xsimd::batch<float, A>::size;
    alignas(64) std::int32_t at[W];
    alignas(64) float out[W];
    index.store_aligned(at);
    for (std::size_t l = 0; l < W; ++l) out[l] = src[at[l]];
    return xsimd::batch<float, A>::load_aligned(out);
}

template <class A, class T>
inline std::size_t compress_store(const xsimd::batch<T, A>& v, unsigned bits, T* dst) {
    alignas(64) T tmp[xsimd::batch<T, A>::size];
    v.store_aligned(tmp);
    std::size_t n = 0;
    for (std::size_t l = 0; l < xsimd::batch<T, A>::size; ++l)
        if (bits >> l & 1u) dst[n++] = tmp[l];
    return n;
}

#if defined(__AVX512F__)
inline xsimd::batch<float, xsimd::avx512bw> gather_floats(const float* src,
                                                          const xsimd::batch<std::int32_t, xsimd::avx512bw>& index) {
    return _mm512_i32gather_ps(index, src, 4);
}
inline unsigned lane_bits(const xsimd::batch_bool<float, xsimd::avx512bw>& m) { return unsigned(m.data); }
inline std::size_t compress_store(const xsimd::batch<float, xsimd::avx512bw>& v, unsigned bits, float* dst) {
    // Compress in a register, then one full store: faster than a compressing store.
    _mm512_storeu_ps(dst, _mm512_maskz_compress_ps(__mmask16(bits), v));
    return std::size_t(__builtin_popcount(bits));
}
inline std::size_t compress_store(const xsimd::batch<std::int32_t, xsimd::avx512bw>& v, unsigned bits,
                                  std::int32_t* dst) {
    _mm512_storeu_si512(dst, _mm512_maskz_compress_epi32(__mmask16(bits), v));
    return std::size_t(__builtin_popcount(bits));
}
#endif

#if defined(__AVX2__)
namespace compress_detail {
/// For each 8-bit mask, the lane indices of its set bits first (packed 4 bits each).
constexpr std::array<std::uint32_t, 256> make_table() {
    std::array<std::uint32_t, 256> t{};
    for (unsigned m = 0; m < 256; ++m) {
        std::uint32_t packed = 0;
        unsigned n = 0;
        for (unsigned l = 0; l < 8; ++l)
            if (m >> l & 1u) packed |= l << (4 * n++);
        t[m] = packed;
    }
    return t;
}
inline constexpr std::array<std::uint32_t, 256> kTable = make_table();
inline __m256i permutation(unsigned bits) {
    const __m256i packed = _mm256_set1_epi32(int(kTable[bits & 0xffu]));
    const __m256i shifts = _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28);
    return _mm256_and_si256(_mm256_srlv_epi32(packed, shifts), _mm256_set1_epi32(7));
}
}  // namespace compress_detail
inline xsimd::batch<float, xsimd::fma3<xsimd::avx2>> gather_floats(
    const float* src, const xsimd::batch<std::int32_t, xsimd::fma3<xsimd::avx2>>& index) {
    return _mm256_i32gather_ps(src, index, 4);
}
inline unsigned lane_bits(const xsimd::batch_bool<float, xsimd::fma3<xsimd::avx2>>& m) {
    return unsigned(_mm256_movemask_ps(m));
}
inline std::size_t compress_store(const xsimd::batch<float, xsimd::fma3<xsimd::avx2>>& v, unsigned bits, float* dst) {
    _mm256_storeu_ps(dst, _mm256_permutevar8x32_ps(v, compress_detail::permutation(bits)));
    return std::size_t(__builtin_popcount(bits));
}
inline std::size_t compress_store(const xsimd::batch<std::int32_t, xsimd::fma3<xsimd::avx2>>& v, unsigned bits,
                                  std::int32_t* dst) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst),
                        _mm256_permutevar8x32_epi32(v, compress_detail::permutation(bits)));
    return std::size_t(__builtin_popcount(bits));
}
#endif

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
