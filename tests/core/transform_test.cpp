#include <doctest/doctest.h>

#include <random>

#include "core/transform.h"

using namespace streamrt;

TEST_CASE("Md x affine_inverse(Md) is the identity and Mn keeps normals perpendicular under non-uniform scale") {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(-3, 3), s(0.1, 4), ang(-180, 180);
    for (int i = 0; i < 200; ++i) {
        CAPTURE(i);
        const glm::dmat4 md = translate_matrix({u(rng), u(rng), u(rng)}) * rotate_z_matrix(ang(rng)) *
                              rotate_y_matrix(ang(rng)) * rotate_x_matrix(ang(rng)) *
                              scale_matrix({s(rng), s(rng), s(rng)});
        const glm::dmat4x3 mi = affine_inverse(glm::dmat4x3(md));
        const glm::dmat4 id = md * glm::dmat4(mi);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) CHECK(id[c][r] == doctest::Approx(c == r ? 1.0 : 0.0).epsilon(1e-12));
        // A tangent t and normal n of a canonical surface stay perpendicular in the world.
        const glm::dvec3 n = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
        const glm::dvec3 t = glm::cross(n, glm::dvec3(0.3, 0.5, 0.7));
        // The engines' Mn: apply_normal over Mi's rows (its linear part transposed).
        const glm::dvec3 tw = transform_vector(md, t);
        const Vec3d nv = apply_normal(RowsOf{mi}, Vec3d{n.x, n.y, n.z});
        const glm::dvec3 nw{nv.x, nv.y, nv.z};
        CHECK(glm::dot(tw, nw) == doctest::Approx(0.0).epsilon(1e-12));
        CHECK(glm::length(nw) == doctest::Approx(1.0));
    }
}

TEST_CASE("rotations: exact quarter turns and the right-hand rule") {
    const glm::dvec3 x = transform_vector(rotate_z_matrix(90), {1, 0, 0});
    CHECK(x == glm::dvec3(0, 1, 0));
    CHECK(transform_vector(rotate_x_matrix(90), {0, 1, 0}) == glm::dvec3(0, 0, 1));
    CHECK(transform_vector(rotate_y_matrix(90), {0, 0, 1}) == glm::dvec3(1, 0, 0));
    CHECK(transform_point(translate_matrix({1, 2, 3}), {1, 1, 1}) == glm::dvec3(2, 3, 4));
    CHECK(relative_determinant(scale_matrix({1, 1, 0})) == 0.0);
    CHECK(relative_determinant(scale_matrix({1e4, 1e-3, 1})) == doctest::Approx(1.0));
}
