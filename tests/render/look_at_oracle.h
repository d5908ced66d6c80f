#pragma once
// The look-at camera of docs/scene-format.md ("Camera": df = 1, ry = tan(fov/2),
// rx = ry × width / height, x right, y up, the view along `look - eye`), written here in double
// from the docs and nothing else: the generate kernels' tests hold their rays against it
// instead of against the engine's own camera and sample templates, which the kernels share.
#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

namespace test {

struct LookAtOracle {
    glm::dvec3 eye, forward, right, up;
    double rx, ry;
    int width, height;

    LookAtOracle(glm::dvec3 eye_, glm::dvec3 look, glm::dvec3 up_hint, double fov_degrees, int w, int h)
        : eye(eye_), width(w), height(h) {
        forward = glm::normalize(look - eye);
        right = glm::normalize(glm::cross(forward, up_hint));
        up = glm::cross(right, forward);
        ry = std::tan(fov_degrees * std::numbers::pi / 360.0);
        rx = ry * double(w) / double(h);
    }
    /// Unit direction through image position (px, py), in pixels from the top-left corner.
    glm::dvec3 direction(double px, double py) const {
        const double u = 2.0 * px / width - 1.0, v = 1.0 - 2.0 * py / height;
        return glm::normalize(forward + u * rx * right + v * ry * up);
    }
    /// The image position a ray from `from` along `d` meets when seen from the eye: where the
    /// line through the eye and the ray's point at `depth` along the view crosses the screen.
    glm::dvec2 image_position(glm::dvec3 from, glm::dvec3 d, double depth = 1.0) const {
        const double t = (depth - glm::dot(from - eye, forward)) / glm::dot(d, forward);
        const glm::dvec3 q = (from + t * d - eye) / depth - forward;  // on the screen at unit distance
        return {(glm::dot(q, right) / rx + 1.0) * width / 2.0, (1.0 - glm::dot(q, up) / ry) * height / 2.0};
    }
};

}  // namespace test
