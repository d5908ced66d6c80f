#pragma once
// The smallest or largest lane of a batch, for the packet walks (mesh_kernel.h, accel_kernel.h).
// Included only by kernels/isa_*.cpp through intersect_kernel.h, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <immintrin.h>

#include <cstddef>
#include <limits>
#include <type_traits>

#include "simd/isa_namespace.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// The smallest or largest lane of v (never NaN here: the walks' distances are not): a
/// shuffle tree on the x86 levels. A store and a loop over the lanes made a chain of 15
/// dependent compares for 16 lanes, run for every box a packet enters; the shuffle tree
/// made primary rays on the 1.3M-triangle mesh about 10 % faster (docs/performance.md).
template <bool Largest, class B>
inline float lanes_extreme(const B& v) {
    using A = typename B::arch_type;
    const auto pick = [](auto a, auto b) {
        if constexpr (Largest) return _mm_max_ps(a, b);
        else return _mm_min_ps(a, b);
    };
    __m128 q;
    if constexpr (std::is_base_of_v<xsimd::avx512f, A>) {
        if constexpr (Largest) return _mm512_reduce_max_ps(v);
        else return _mm512_reduce_min_ps(v);
    } else if constexpr (std::is_base_of_v<xsimd::avx, A>) {
        q = pick(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    } else if constexpr (std::is_base_of_v<xsimd::sse2, A>) {
        q = v;
    } else {
        alignas(64) float a[B::size];
        v.store_aligned(a);
        float r = a[0];
        for (std::size_t l = 1; l < B::size; ++l) r = Largest ? (r > a[l] ? r : a[l]) : (r < a[l] ? r : a[l]);
        return r;
    }
    q = pick(q, _mm_movehl_ps(q, q));
    q = pick(q, _mm_shuffle_ps(q, q, 1));
    return _mm_cvtss_f32(q);
}
template <class B>
inline float lanes_max(const B& v) {
    return lanes_extreme<true>(v);
}
/// The smallest lane of v among those of m (infinity when m has none).
template <class B>
inline float lanes_min_where(const B& v, const decltype(B(0.f) < B(0.f))& m) {
    return lanes_extreme<false>(xsimd::select(m, v, B(std::numeric_limits<float>::infinity())));
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
