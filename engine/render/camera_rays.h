#pragma once
// Primary rays of the handout's canonical camera: eye E = (0,0,1), screen [-1,1]^2 in z = 0,
// both placed in the world by Md. The ray through screen point P is [Md E, Md (P - E)).
// A camera with an aperture is a thin lens instead (lens_ray): the ray leaves from a point of
// the lens disc and passes through the point where the pinhole ray meets the plane in focus.
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
    // Thin lens (camera aperture= and focus=): the lens disc of radius lens_radius around the
    // eye, spanned by the unit vectors lens_u and lens_v (Md's x and y axes, made orthogonal);
    // the plane in focus is where the pinhole ray origin + s (du x + dv y + dback) has
    // s = focus_scale (focus / |dback|: the plane parallel to the screen, `focus` along the
    // view axis). lens_radius = 0 is the pinhole, and the engines then never call lens_ray.
    Vec3T<T> lens_u{}, lens_v{};
    T lens_radius = T(0), focus_scale = T(1);

    static CameraRays from(const Scene& scene) { return from(scene.camera, scene.settings); }
    /// The camera for an image of these settings (a render job's, which may override the
    /// scene's size and samples).
    static CameraRays from(const Camera& camera, const RenderSettings& s) {
        const glm::dmat4 md = camera.world_from_canonical(s.width, s.height);
        const glm::dvec3 e = transform_point(md, {0.0, 0.0, 1.0});
        const auto v = [](const glm::dvec3& a) { return Vec3T<T>{T(a.x), T(a.y), T(a.z)}; };
        // A pixel spans 2 / width of the canonical screen (|Md x| per unit) at distance
        // |Md z| from the eye; samples are spread over it sqrt(spp) to a side.
        const double pixel = std::min(2.0 * glm::length(glm::dvec3(md[0])) / s.width,
                                      2.0 * glm::length(glm::dvec3(md[1])) / s.height) /
                             glm::length(glm::dvec3(md[2]));
        const glm::dvec3 lu = glm::normalize(glm::dvec3(md[0]));
        const glm::dvec3 lv = glm::normalize(glm::dvec3(md[1]) - lu * glm::dot(lu, glm::dvec3(md[1])));
        return {v(e),
                v(glm::dvec3(md[0])),
                v(glm::dvec3(md[1])),
                v(-glm::dvec3(md[2])),
                T(1.0 / s.width),
                T(1.0 / s.height),
                T(pixel / std::sqrt(double(s.spp))),
                v(lu),
                v(lv),
                T(camera.aperture),
                T(camera.focus_distance(md) / glm::length(glm::dvec3(md[2])))};
    }

    bool has_lens() const { return lens_radius > T(0); }

    /// Unit direction through image position (px, py), in pixels from the top-left corner.
    Vec3T<T> direction(T px, T py) const { return direction_of<T>(px, py); }
    /// The same for a batch of positions (the stream engine's generate kernel).
    template <class B>
        requires simd::is_batch<B>
    Vec3T<B> direction(const B& px, const B& py) const { return direction_of<B>(px, py); }

    /// Thin lens: the ray for image position (px, py) leaving the lens at (lx, ly) of the unit
    /// disc (sampling.h's lens_sample): origin eye + lens_radius (lx lens_u + ly lens_v), unit
    /// direction towards the pinhole ray's point on the plane in focus. V is T or a batch.
    template <class V>
    void lens_ray(const V& px, const V& py, const V& lx, const V& ly, Vec3T<V>& o, Vec3T<V>& d) const {
        const Vec3T<V> off = lanes<V>(lens_u) * (lx * V(lens_radius)) + lanes<V>(lens_v) * (ly * V(lens_radius));
        o = lanes<V>(origin) + off;
        d = normalize(screen_vector(px, py) * V(focus_scale) - off);
    }

  private:
    template <class V>
    static Vec3T<V> lanes(const Vec3T<T>& a) {
        return Vec3T<V>{V(a.x), V(a.y), V(a.z)};
    }
    /// Md (P - E) for the screen point P of image position (px, py), not normalised.
    template <class V>
    Vec3T<V> screen_vector(const V& px, const V& py) const {
        const V u = V(T(2)) * px * V(inv_width) - V(T(1));
        const V w = V(T(1)) - V(T(2)) * py * V(inv_height);
        return lanes<V>(du) * u + lanes<V>(dv) * w + lanes<V>(dback);
    }
    template <class V>
    Vec3T<V> direction_of(const V& px, const V& py) const {
        return normalize(screen_vector(px, py));
    }
};

}  // namespace streamrt
