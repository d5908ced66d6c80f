#pragma once
// Primary rays of the handout's canonical camera: eye E = (0,0,1), screen [-1,1]^2 in z = 0,
// both placed in the world by Md. The ray through screen point P is [Md E, Md (P - E)).
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "scene/scene.h"
#include "simd/lanes.h"

namespace streamrt {

template <class T>
struct CameraRays {
    Vec3T<T> origin;         ///< Md E
    Vec3T<T> du, dv, dback;  ///< Md's linear part applied to x, y and -z
    T inv_width, inv_height;
    T spread;  ///< angle between neighbouring samples at the image centre (ray-cone spread)

    static CameraRays from(const Scene& scene) {
        const RenderSettings& s = scene.settings;
        const glm::dmat4 md = scene.camera.world_from_canonical(s.width, s.height);
        const glm::dvec3 e = transform_point(md, {0.0, 0.0, 1.0});
        const auto v = [](const glm::dvec3& a) { return Vec3T<T>{T(a.x), T(a.y), T(a.z)}; };
        // A pixel spans 2 / width of the canonical screen (|Md x| per unit) at distance
        // |Md z| from the eye; samples are spread over it sqrt(spp) to a side.
        const double pixel = std::min(2.0 * glm::length(glm::dvec3(md[0])) / s.width,
                                      2.0 * glm::length(glm::dvec3(md[1])) / s.height) /
                             glm::length(glm::dvec3(md[2]));
        return {v(e), v(glm::dvec3(md[0])), v(glm::dvec3(md[1])), v(-glm::dvec3(md[2])),
                T(1.0 / s.width), T(1.0 / s.height), T(pixel / std::sqrt(double(s.spp)))};
    }

    /// Unit direction through image position (px, py), in pixels from the top-left corner.
    Vec3T<T> direction(T px, T py) const { return direction_of<T>(px, py); }
    /// The same for a batch of positions (the stream engine's generate kernel).
    template <class B>
        requires simd::is_batch<B>
    Vec3T<B> direction(const B& px, const B& py) const { return direction_of<B>(px, py); }

  private:
    template <class V>
    Vec3T<V> direction_of(const V& px, const V& py) const {
        const auto lanes = [](const Vec3T<T>& a) { return Vec3T<V>{V(a.x), V(a.y), V(a.z)}; };
        const V u = V(T(2)) * px * V(inv_width) - V(T(1));
        const V w = V(T(1)) - V(T(2)) * py * V(inv_height);
        return normalize(lanes(du) * u + lanes(dv) * w + lanes(dback));
    }
};

}  // namespace streamrt
