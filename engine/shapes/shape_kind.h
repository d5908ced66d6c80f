#pragma once
// The kinds of shape a scene object can be: the lowest layer, so the shape math, the scene
// store and the kernels all name them without depending on each other.
#include <cstdint>

namespace streamrt {

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
/// The keyword of each kind in the scene format.
constexpr const char* shape_kind_name(ShapeKind k) {
    switch (k) {
        case ShapeKind::Sphere: return "sphere";
        case ShapeKind::Cube: return "cube";
        case ShapeKind::Cylinder: return "cylinder";
        case ShapeKind::Cone: return "cone";
        case ShapeKind::Torus: return "torus";
        case ShapeKind::Plane: return "plane";
        case ShapeKind::Mesh: return "mesh";
    }
    return "?";
}

}  // namespace streamrt
