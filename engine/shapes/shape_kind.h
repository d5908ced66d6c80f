#pragma once
// The kinds of shape a scene object can be: the lowest layer, so the shape math, the scene
// store and the kernels all name them without depending on each other.
#include <cstdint>

namespace streamrt {

/// Canonical shapes (docs/scene-format.md gives each exact definition). Each kind but Mesh
/// is declared by its math file and registered, in this order, in shapes/shapes.h
/// (CanonicalShapes), which checks at compile time that the two agree.
enum class ShapeKind : std::uint8_t {
    Sphere,    ///< unit sphere centred at the origin
    Cube,      ///< [-1,1]^3
    Cylinder,  ///< radius 1 around the y axis, y in [-1,1], both ends capped
    Cone,      ///< base radius 1 at y=-1, apex at y=+1, base capped
    Torus,     ///< major radius 1 around the y axis in the xz-plane, minor radius per object
    Plane,     ///< y = 0, normal +y, infinite
    Disk,      ///< x^2 + z^2 <= 1 in the plane y = 0, normal +y
    Mesh,      ///< a triangle mesh in its own coordinates (engine/mesh/mesh.h); not closed-form; last
};
inline constexpr int kShapeKindCount = int(ShapeKind::Mesh) + 1;

}  // namespace streamrt
