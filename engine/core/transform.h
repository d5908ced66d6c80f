#pragma once
// The handout's three homogeneous matrices: Md (canonical -> world), Mi = Md^-1 (world ->
// canonical) and Mn = (Md^-1)^T restricted to 3x3 (normals). Scenes store Md only; the engines
// derive Mi once (affine_inverse) and apply Mn as Mi's linear part transposed.
#include <glm/glm.hpp>

#include "core/vec3.h"

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
/// Mn n = (Mi's linear part)^T n, normalised: n times that part as a row vector.
inline glm::dvec3 transform_normal(const glm::dmat4x3& mi, const glm::dvec3& n) {
    return glm::normalize(n * glm::dmat3(mi));
}

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
