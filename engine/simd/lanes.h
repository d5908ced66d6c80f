#pragma once
// Shims so one template compiles for scalars (float, double) and xsimd batches.
// xsimd 8.1 has scalar sqrt/fma but no scalar select/any/all.
#include <xsimd/xsimd.hpp>
#include <xmmintrin.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "simd/isa_namespace.h"

namespace streamrt::simd {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

inline float select(bool m, float a, float b) { return m ? a : b; }
inline double select(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline bool all(bool m) { return m; }
inline float abs(float a) { return std::fabs(a); }
inline double abs(double a) { return std::fabs(a); }
inline float min(float a, float b) { return a < b ? a : b; }
inline double min(double a, double b) { return a < b ? a : b; }
inline float max(float a, float b) { return a > b ? a : b; }
inline double max(double a, double b) { return a > b ? a : b; }
inline float sign_of(float a) { return std::copysign(1.f, a); }
inline double sign_of(double a) { return std::copysign(1.0, a); }

template <class B>
inline constexpr bool is_batch = xsimd::is_batch<B>::value;
template <class M>
inline constexpr bool is_batch_bool = xsimd::is_batch_bool<M>::value;

// Batch forms for qualified calls (simd::select(...)). They are deliberately generic: for an
// unqualified call, xsimd's own, more specialised overloads (found by argument-dependent
// lookup) win the partial ordering, so the two never make a call ambiguous.
template <class M, class B>
    requires is_batch<B>
inline B select(const M& m, const B& a, const B& b) { return xsimd::select(m, a, b); }
template <class M>
    requires is_batch_bool<M>
inline bool any(const M& m) { return xsimd::any(m); }
template <class M>
    requires is_batch_bool<M>
inline bool all(const M& m) { return xsimd::all(m); }
/// Lane-wise exclusive or of two masks. Written with and/or/not because xsimd 8.1 gets the
/// direct forms wrong: on AVX-512, mask ^ mask is an OR; on SSE2, mask != mask compares the
/// all-ones lanes as doubles (NaN), so it is always true.
inline bool mask_xor(bool a, bool b) { return a != b; }
template <class M>
    requires is_batch_bool<M>
inline M mask_xor(const M& a, const M& b) { return (a && !b) || (!a && b); }

template <class B>
    requires is_batch<B>
inline B abs(const B& a) { return xsimd::abs(a); }
template <class B>
    requires is_batch<B>
inline B min(const B& a, const B& b) { return xsimd::min(a, b); }
template <class B>
    requires is_batch<B>
inline B max(const B& a, const B& b) { return xsimd::max(a, b); }

/// Whether every lane of an unsigned integer is 0.
inline bool none_set(std::uint32_t x) { return x == 0; }
template <class A>
inline bool none_set(const xsimd::batch<std::uint32_t, A>& x) {
    return xsimd::all(x == xsimd::batch<std::uint32_t, A>(0u));
}

/// An unsigned integer below 2^31 as a float (exact below 2^24).
inline float to_float(std::uint32_t h) { return float(h); }
template <class A>
inline xsimd::batch<float, A> to_float(const xsimd::batch<std::uint32_t, A>& h) {
    return xsimd::to_float(xsimd::bitwise_cast<xsimd::batch<std::int32_t, A>>(h));
}

template <class T, class A>
inline xsimd::batch<T, A> sign_of(const xsimd::batch<T, A>& a) {
    return xsimd::copysign(xsimd::batch<T, A>(T(1)), a);
}

using std::sqrt;
using xsimd::sqrt;

/// a * b + c rounded twice, at every level. xsimd::fma fuses at AVX2 and AVX-512 only (one
/// rounding), so the kernels write this instead: the pictures are then the same bits at every
/// level (docs/architecture.md, "Kernels and instruction sets"). The kernel files are built
/// with -ffp-contract=off, so the compiler does not fuse it either.
template <class B>
inline B mul_add(const B& a, const B& b, const B& c) {
    return a * b + c;
}

/// x^y. Scalars: std::pow. Batches: xsimd::pow, whose polynomials are evaluated with
/// xsimd::fma; the AVX2 and AVX-512 levels run it on plain-AVX2 batches (no fma3), so it
/// rounds like the SSE levels and gives the same bits (an unqualified call on batches would
/// pick xsimd::pow through argument-dependent lookup: call simd::pow).
inline float pow(float x, float y) { return std::pow(x, y); }
inline double pow(double x, double y) { return std::pow(x, y); }
template <class B>
    requires is_batch<B>
inline B pow(const B& x, const B& y) { return xsimd::pow(x, y); }
#if defined(__AVX2__)
inline xsimd::batch<float, xsimd::fma3<xsimd::avx2>> pow(const xsimd::batch<float, xsimd::fma3<xsimd::avx2>>& x,
                                                          const xsimd::batch<float, xsimd::fma3<xsimd::avx2>>& y) {
    using P = xsimd::batch<float, xsimd::avx2>;
    return __m256(xsimd::pow(P(__m256(x)), P(__m256(y))));
}
#endif
#if defined(__AVX512F__)
inline xsimd::batch<float, xsimd::avx512bw> pow(const xsimd::batch<float, xsimd::avx512bw>& x,
                                                const xsimd::batch<float, xsimd::avx512bw>& y) {
    using P = xsimd::batch<float, xsimd::avx2>;
    const __m512d xd = _mm512_castps_pd(x), yd = _mm512_castps_pd(y);
    const P lo = xsimd::pow(P(_mm512_castps512_ps256(x)), P(_mm512_castps512_ps256(y)));
    const P hi = xsimd::pow(P(_mm256_castpd_ps(_mm512_extractf64x4_pd(xd, 1))),
                            P(_mm256_castpd_ps(_mm512_extractf64x4_pd(yd, 1))));
    return _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castps_pd(_mm512_castps256_ps512(lo)), _mm256_castps_pd(hi), 1));
}
#endif

/// The element type behind V (float for batch<float>, double for double, ...).
template <class V>
struct scalar_of { using type = V; };
template <class T, class A>
struct scalar_of<xsimd::batch<T, A>> { using type = T; };
template <class V>
using scalar_t = typename scalar_of<V>::type;

/// Flush-to-zero and denormals-are-zero (MXCSR bits 15 and 6) for the scope of a kernel
/// call, restored on exit. Rays with denormal components (or products that underflow) ran
/// 30 to 60 times slower per operation through the microcode assists; with the flags they
/// cost what ordinary rays cost, and a denormal direction reads as zero (a clean miss).
/// Every kernel entry point takes one, so the picture does not depend on the caller's mode.
class FlushDenormals {
  public:
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }
    ~FlushDenormals() { _mm_setcsr(saved_); }
    FlushDenormals(const FlushDenormals&) = delete;
    FlushDenormals& operator=(const FlushDenormals&) = delete;

  private:
    unsigned saved_;
};

STREAMRT_ISA_END

/// Starts loading the cache lines of [p, p + bytes): for data a walk will read after testing
/// nearer things (a leaf met now, popped later).
inline void prefetch_lines(const void* p, std::size_t bytes) {
    const char* c = static_cast<const char*>(p);
    for (const char* end = c + bytes; c < end; c += 64) __builtin_prefetch(c);
}

/// Widest batch we build (AVX-512: 16 floats). Streams are padded to it in every build so the
/// layout is the same at 4, 8 and 16 lanes and aligned loads are always legal.
inline constexpr std::size_t kMaxLanes = 16;
inline constexpr std::size_t kAlign = 64;
template <class T>
using AlignedVec = std::vector<T, xsimd::aligned_allocator<T, kAlign>>;
STREAMRT_ISA_BEGIN
constexpr std::size_t round_up_lanes(std::size_t n) { return (n + kMaxLanes - 1) / kMaxLanes * kMaxLanes; }
STREAMRT_ISA_END

}  // namespace streamrt::simd
