#pragma once
// The scene model of the handout: lights, shapes (canonical shape + Md/Mn/Mi + material),
// a camera placed by Md, and the render settings. Everything here is in double; the stream
// engine converts to its own float tables when it builds its pipeline.
#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/transform.h"

namespace streamrt {

struct Mesh;

/// Canonical shapes (docs/scene-format.md gives each exact definition).
enum class ShapeKind : std::uint8_t {
    Sphere,    ///< unit sphere centred at the origin
    Cube,      ///< [-1,1]^3
    Cylinder,  ///< radius 1 around the y axis, y in [-1,1], both ends capped
    Cone,      ///< base radius 1 at y=-1, apex at y=+1, base capped
    Torus,     ///< major radius 1 around the y axis in the xz-plane, minor radius per object
    Plane,     ///< y = 0, normal +y, infinite
    Mesh,      ///< a triangle mesh in its own coordinates (engine/mesh/mesh.h); not closed-form
};
inline constexpr int kShapeKindCount = 7;
const char* shape_kind_name(ShapeKind k);

struct Material {
    glm::dvec3 color{1.0, 1.0, 1.0};
    double ambi = 1.0;   ///< weight of the ambient term (degree 2)
    double diff = 1.0;   ///< weight of the Lambert term (degree 2)
    double spec = 0.0;   ///< Phong highlight weight (degree 2, optional)
    double shininess = 32.0;
    double refl = 0.0;   ///< mirror reflection weight (degree 3)
    double trans = 0.0;  ///< transmission weight (degree 4)
    double ior = 1.0;    ///< index of refraction of the inside
    bool checker = false;
    glm::dvec3 checker_color{0.0, 0.0, 0.0};
    double cell = 1.0;  ///< checker cell side, world units
};

struct Object {
    ShapeKind kind = ShapeKind::Sphere;
    double minor = 0.25;  ///< torus minor radius (canonical units); unused by other shapes
    std::shared_ptr<const Mesh> mesh;  ///< Mesh only: the triangles, shared by every object using the file
    bool smooth = false;  ///< Mesh only: interpolated vertex normals instead of the flat face normal
    Material material;
    Transform xf;  ///< Md, Mi, Mn
    SourceLoc where;  ///< the statement that made it, for messages

    /// The per-object shape parameter the kernels and shading receive: the torus minor
    /// radius, 1 for a smooth mesh, 0 for a flat one.
    double param() const { return kind == ShapeKind::Mesh ? (smooth ? 1.0 : 0.0) : minor; }
};

enum class LightKind : std::uint8_t { Point, Spot, Directional };

struct Light {
    LightKind kind = LightKind::Point;
    glm::dvec3 pos{0.0, 0.0, 0.0};
    glm::dvec3 dir{0.0, -1.0, 0.0};  ///< normalised; spot axis or directional travel direction
    glm::dvec3 color{1.0, 1.0, 1.0};
    double angle = 30.0;  ///< spot: half-angle of the cone, degrees
};

/// The handout's canonical camera (eye (0,0,1), screen [-1,1]^2 in z=0) placed by Md.
/// Two forms: Md given directly (homothety rx, ry, df then the listed transforms), or
/// look-at (eye, look, up, vertical fov), converted to Md once the image aspect is known.
struct Camera {
    bool look_at = false;
    glm::dmat4 md{1.0};  ///< explicit form
    glm::dvec3 eye{0.0, 0.0, 5.0}, look{0.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
    double fov = 45.0;  ///< look-at form: vertical field of view, degrees

    /// Md for an image of width x height pixels (the look-at form keeps square pixels).
    glm::dmat4 world_from_canonical(int width, int height) const;
};

enum class Calibration : std::uint8_t { Clamp, Normalize };
enum class SamplePattern : std::uint8_t { Stratified, Grid, Random };

struct RenderSettings {
    int width = 640;
    int height = 480;
    int spp = 1;
    int depth = 5;   ///< maximum number of reflection/refraction bounces after the primary hit
    int degree = 5;  ///< 0 flat .. 5 shadows, cumulative (handout)
    double ambient = 0.1;  ///< alpha, the ambient fraction
    glm::dvec3 background{0.0, 0.0, 0.0};
    Calibration calibration = Calibration::Clamp;
    SamplePattern pattern = SamplePattern::Stratified;
    std::string output = "out.png";
};

struct Scene {
    std::string path;  ///< the file it was read from
    RenderSettings settings;
    Camera camera;
    std::vector<Light> lights;
    std::vector<Object> objects;
};

}  // namespace streamrt
