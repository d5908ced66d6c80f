#pragma once
// The handout's three homogeneous matrices: Md (canonical -> world), Mi = Md^-1 (world ->
// canonical) and Mn = (Md^-1)^T restricted to 3x3 (normals). Scenes store Md only; the engines
// derive Mi once (affine_inverse) and apply Mn as Mi's linear part transposed.
#include <glm/glm.hpp>

#include "core/vec3.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {

inline Vec3d to_vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
inline glm::dvec3 to_glm(const Vec3d& v) { return {v.x, v.y, v.z}; }

/// Points take the translation, vectors do not, normals go through Mn (pbrt's naming).
inline glm::dvec3 transform_point(const glm::dmat4& m, const glm::dvec3& p) {
    return glm::dvec3(m * glm::dvec4(p, 1.0));
}
inline glm::dvec3 transform_vector(const glm::dmat4& m, const glm::dvec3& v) {
    return glm::dmat3(m) * v;
}

/// An affine map's top three rows read row-major, m[4 r + c] = row r, column c, from a glm
/// dmat4x3 (stored by columns): the form apply_point / apply_vector / apply_normal read.
struct RowsOf {
    const glm::dmat4x3& m;
    double operator[](int k) const { return m[k & 3][k >> 2]; }
};

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// The transform helpers of both engines: Rows is a row-major 3x4 (a float*, RowsOf, or rows
/// of batches), V double, float or a batch. One evaluation order, m0 x + (m1 y + (m2 z + m3)),
/// each product and sum rounded on its own (simd::mul_add, never fused), so the scalar and
/// SIMD paths, at every ISA level, round alike.
template <class Rows, class V>
inline Vec3T<V> apply_point(const Rows& m, const Vec3T<V>& p) {
    using simd::mul_add;
    return {mul_add(V(m[0]), p.x, mul_add(V(m[1]), p.y, mul_add(V(m[2]), p.z, V(m[3])))),
            mul_add(V(m[4]), p.x, mul_add(V(m[5]), p.y, mul_add(V(m[6]), p.z, V(m[7])))),
            mul_add(V(m[8]), p.x, mul_add(V(m[9]), p.y, mul_add(V(m[10]), p.z, V(m[11]))))};
}
template <class Rows, class V>
inline Vec3T<V> apply_vector(const Rows& m, const Vec3T<V>& v) {
    using simd::mul_add;
    return {mul_add(V(m[0]), v.x, mul_add(V(m[1]), v.y, V(m[2]) * v.z)),
            mul_add(V(m[4]), v.x, mul_add(V(m[5]), v.y, V(m[6]) * v.z)),
            mul_add(V(m[8]), v.x, mul_add(V(m[9]), v.y, V(m[10]) * v.z))};
}
/// Mn n, not normalised, with Mn = (Mi's linear part) transposed, read from Mi's rows.
template <class Rows, class V>
inline Vec3T<V> normal_direction(const Rows& mi, const Vec3T<V>& n) {
    using simd::mul_add;
    return {mul_add(V(mi[0]), n.x, mul_add(V(mi[4]), n.y, V(mi[8]) * n.z)),
            mul_add(V(mi[1]), n.x, mul_add(V(mi[5]), n.y, V(mi[9]) * n.z)),
            mul_add(V(mi[2]), n.x, mul_add(V(mi[6]), n.y, V(mi[10]) * n.z))};
}
/// Mn n, normalised.
template <class Rows, class V>
inline Vec3T<V> apply_normal(const Rows& mi, const Vec3T<V>& n) {
    return normalize(normal_direction(mi, n));
}

STREAMRT_ISA_END

/// The inverse of an affine map stored as its top three rows (glm: 4 columns of 3): the
/// linear part inverted (cofactors, double), the translation taken back through it.
inline glm::dmat4x3 affine_inverse(const glm::dmat4x3& m) {
    const glm::dmat3 a = glm::inverse(glm::dmat3(m));
    return glm::dmat4x3(a[0], a[1], a[2], -(a * m[3]));
}

/// Elementary transforms (angles in degrees), the vocabulary of the scene file.
glm::dmat4 scale_matrix(const glm::dvec3& s);
glm::dmat4 translate_matrix(const glm::dvec3& t);
glm::dmat4 rotate_x_matrix(double degrees);
glm::dmat4 rotate_y_matrix(double degrees);
glm::dmat4 rotate_z_matrix(double degrees);

/// |det| of the linear part relative to the product of its column lengths: 0 for a
/// singular matrix, 1 for a rotation; scale-free, so tiny but valid objects pass.
double relative_determinant(const glm::dmat4& m);

}  // namespace streamrt
