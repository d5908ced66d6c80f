#pragma once
// simd::gather(src, index): the floats src[index[l]] of every lane. xsimd 8.1 gathers with
// one instruction on AVX2 but lane by lane (an insert per lane) for its avx512bw batches;
// this calls the AVX-512 instruction there. Other levels: xsimd's.
#include <xsimd/xsimd.hpp>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include <cstdint>

#include "simd/isa_namespace.h"

namespace streamrt::simd {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

template <class A>
inline xsimd::batch<float, A> gather(const float* src, const xsimd::batch<std::int32_t, A>& index) {
    return xsimd::batch<float, A>::gather(src, index);
}
#if defined(__AVX512F__)
inline xsimd::batch<float, xsimd::avx512bw> gather(const float* src,
                                                   const xsimd::batch<std::int32_t, xsimd::avx512bw>& index) {
    return _mm512_i32gather_ps(index, src, 4);
}
#endif

STREAMRT_ISA_END
}  // namespace streamrt::simd
