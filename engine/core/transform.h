#pragma once
// The handout's three homogeneous matrices kept together: Md (canonical -> world),
// Mi = Md^-1 (world -> canonical) and Mn = (Md^-1)^T restricted to 3x3 (normals).
#include <glm/glm.hpp>

#include "core/vec3.h"

namespace streamrt {

struct Transform {
    glm::dmat4 md{1.0};  ///< direct: canonical -> world
    glm::dmat4 mi{1.0};  ///< inverse: world -> canonical
    glm::dmat3 mn{1.0};  ///< normals: inverse-transpose of Md's linear part

    /// Builds the three from Md; the caller has checked Md is invertible.
    static Transform from_direct(const glm::dmat4& md) {
        Transform t;
        t.md = md;
        t.mi = glm::inverse(md);
        t.mn = glm::transpose(glm::dmat3(t.mi));
        return t;
    }
};

inline Vec3d to_vec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
inline glm::dvec3 to_glm(const Vec3d& v) { return {v.x, v.y, v.z}; }

/// Points take the translation, vectors do not, normals go through Mn (pbrt's naming).
inline glm::dvec3 transform_point(const glm::dmat4& m, const glm::dvec3& p) {
    return glm::dvec3(m * glm::dvec4(p, 1.0));
}
inline glm::dvec3 transform_vector(const glm::dmat4& m, const glm::dvec3& v) {
    return glm::dmat3(m) * v;
}
inline glm::dvec3 transform_normal(const glm::dmat3& mn, const glm::dvec3& n) {
    return glm::normalize(mn * n);
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
