#pragma once
// Vec3T<V>: a plain {x, y, z} that works for V = double (baseline), float (stream
// shading) and xsimd batches (kernels). Only the operations the shape math needs.
#include <cmath>

#include "simd/isa_namespace.h"

namespace streamrt {

template <class V>
struct Vec3T {
    V x, y, z;
};

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

template <class V>
inline Vec3T<V> operator+(const Vec3T<V>& a, const Vec3T<V>& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
inline Vec3T<V> operator-(const Vec3T<V>& a, const Vec3T<V>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class V>
inline Vec3T<V> operator-(const Vec3T<V>& a) {
    return {-a.x, -a.y, -a.z};
}
template <class V>
inline Vec3T<V> operator*(const Vec3T<V>& a, const V& s) {
    return {a.x * s, a.y * s, a.z * s};
}
template <class V>
inline Vec3T<V> operator*(const V& s, const Vec3T<V>& a) {
    return {a.x * s, a.y * s, a.z * s};
}
template <class V>
inline Vec3T<V> mul(const Vec3T<V>& a, const Vec3T<V>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class V>
inline V dot(const Vec3T<V>& a, const Vec3T<V>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class V>
inline Vec3T<V> cross(const Vec3T<V>& a, const Vec3T<V>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class V>
inline V length(const Vec3T<V>& a) {
    using std::sqrt;
    return sqrt(dot(a, a));
}
template <class V>
inline Vec3T<V> normalize(const Vec3T<V>& a) {
    return a * (V(1) / length(a));
}

STREAMRT_ISA_END

using Vec3d = Vec3T<double>;
using Vec3f = Vec3T<float>;

STREAMRT_ISA_BEGIN

template <class To, class From>
inline Vec3T<To> vec_cast(const Vec3T<From>& a) {
    return {To(a.x), To(a.y), To(a.z)};
}
STREAMRT_ISA_END

}  // namespace streamrt
