#pragma once
// Placeholder, replaced by the robust solver.
#include "core/vec3.h"
#include "shapes/quadratic.h"
namespace streamrt {
template <class V> V torus_hit_t(const Vec3T<V>&, const Vec3T<V>&, V, V, V) { return infinity_v<V>(); }
template <class V> Vec3T<V> torus_normal(const Vec3T<V>& p, V) { return p; }
}  // namespace streamrt
