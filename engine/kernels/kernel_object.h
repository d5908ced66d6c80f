#pragma once
// One object as the stream engine's kernels and its shade stage read it. Raw data only, so
// the per-ISA kernel files touch no container code (see kernels/intersect_kernel.h on why).
#include <cstdint>
#include <type_traits>

#include "mesh/mesh_view.h"
#include "shapes/shape_kind.h"

namespace streamrt {

/// Mi's top three rows (world -> canonical, relative to the eye), broadcast into every lane,
/// the shape parameter (torus minor radius; 1 for a smooth mesh), the object's id in the
/// stream engine's tables and its kind, and for a mesh its triangles and hierarchy. 64 bytes:
/// the id, the flip bit and the kind share a word so that a record is one cache line (see
/// KernelObject).
struct ObjectXf {
    float m[12];  ///< row-major 3x4
    float param;
    std::uint32_t id : 27;  ///< below kMaxSceneObjects (scene/scene.h) = 2^24: the kernels carry it in float lanes
    /// A CSG shape's surface seen where it bounds the result from the outside of the shape (a
    /// subtracted shape's, stream/stream_csg.h): the shade stage turns its normal round.
    std::uint32_t flip : 1;
    std::uint32_t kind : 4;  ///< ShapeKind
    const MeshView* mesh;  ///< ShapeKind::Mesh only (null otherwise); no default, so records can be made unwritten
};
static_assert(std::is_trivially_default_constructible_v<ObjectXf>);
static_assert(sizeof(ObjectXf) == 64, "an object's record is one cache line");
static_assert(kShapeKindCount <= 16, "ObjectXf::kind holds 4 bits");

/// An object's world-space bounding box, padded outwards; the flat kernels skip an object
/// for a whole packet when no ray of it meets the box before its current closest hit.
struct ObjectBounds {
    float lo[3], hi[3];
};

/// The stream engine's record of an object: what the shape kernels need, its kind included.
/// Aligned to a cache line, so that the scene walk that meets a leaf loads one line per object
/// (at 72 bytes most records straddled two). The shade stage reads the same record (Mn is Mi's
/// linear part transposed), so an object's transform is stored once.
struct alignas(64) KernelObject {
    ObjectXf xf;
};

/// What shading needs of an object beside its KernelObject: its colour and material.
struct SurfaceRecord {
    float color[3];
    std::uint32_t material;  ///< index into the stream engine's materials
};

}  // namespace streamrt
