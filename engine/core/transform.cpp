#include "core/transform.h"

#include <cmath>
#include <numbers>

namespace streamrt {

glm::dmat4 scale_matrix(const glm::dvec3& s) {
    glm::dmat4 m(1.0);
    m[0][0] = s.x;
    m[1][1] = s.y;
    m[2][2] = s.z;
    return m;
}

glm::dmat4 translate_matrix(const glm::dvec3& t) {
    glm::dmat4 m(1.0);
    m[3] = glm::dvec4(t, 1.0);
    return m;
}

namespace {
// Exact values for multiples of 90 degrees, so rotate_y=90 maps axes onto axes exactly.
void exact_sin_cos(double degrees, double& s, double& c) {
    const double turns = degrees / 90.0;
    if (turns == std::floor(turns)) {
        // fmod first: a huge angle (1e30 degrees) is an exact multiple of 90 whose quarter
        // turns do not fit in a long.
        const int q = (int(std::fmod(turns, 4.0)) + 4) % 4;
        const double ss[4] = {0, 1, 0, -1}, cc[4] = {1, 0, -1, 0};
        s = ss[q];
        c = cc[q];
        return;
    }
    const double r = degrees * std::numbers::pi / 180.0;
    s = std::sin(r);
    c = std::cos(r);
}
}  // namespace

glm::dmat4 rotate_x_matrix(double degrees) {
    double s, c;
    exact_sin_cos(degrees, s, c);
    glm::dmat4 m(1.0);  // glm is column-major: m[col][row]
    m[1][1] = c;
    m[1][2] = s;
    m[2][1] = -s;
    m[2][2] = c;
    return m;
}

glm::dmat4 rotate_y_matrix(double degrees) {
    double s, c;
    exact_sin_cos(degrees, s, c);
    glm::dmat4 m(1.0);
    m[0][0] = c;
    m[0][2] = -s;
    m[2][0] = s;
    m[2][2] = c;
    return m;
}

glm::dmat4 rotate_z_matrix(double degrees) {
    double s, c;
    exact_sin_cos(degrees, s, c);
    glm::dmat4 m(1.0);
    m[0][0] = c;
    m[0][1] = s;
    m[1][0] = -s;
    m[1][1] = c;
    return m;
}

double relative_determinant(const glm::dmat4& m) {
    const glm::dmat3 l(m);
    const double norms = glm::length(l[0]) * glm::length(l[1]) * glm::length(l[2]);
    if (!(norms > 0.0) || !std::isfinite(norms)) return 0.0;
    return std::fabs(glm::determinant(l)) / norms;
}

}  // namespace streamrt
