#pragma once
// Vectors of lanes: the colour and mask types, and the broadcast and select of a Vec3T, that
// the shading rules and the light kinds write once for double, float and xsimd batches.
#include "core/vec3.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {

template <class T>
using ColorT = Vec3T<T>;

template <class V>
using MaskOf = decltype(V() < V());

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

template <class V, class M>
inline Vec3T<V> select3(const M& m, const Vec3T<V>& a, const Vec3T<V>& b) {
    using simd::select;
    return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

template <class V, class T>
inline Vec3T<V> splat(const Vec3T<T>& a) {
    return {V(a.x), V(a.y), V(a.z)};
}

STREAMRT_ISA_END
}  // namespace streamrt
