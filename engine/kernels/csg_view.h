#pragma once
// CSG objects as the kernels read them (kernels/csg_kernel.h): raw data only, like the other
// kernel records (see kernels/intersect_kernel.h on why).
#include <cstddef>
#include <cstdint>

#include "accel/bvh.h"
#include "kernels/kernel_object.h"
#include "mesh/mesh.h"
#include "kernels/ray_stream.h"
#include "render/csg_layout.h"
#include "scene/scene.h"

namespace streamrt {

/// One CSG object: its root node, its shapes' slots (the reader gives an object's shapes
/// consecutive numbers, so its records are [first_shape, first_shape + shapes) of the
/// layout) and its result's box.
struct CsgObjectView {
    ObjectBounds box;         ///< relative to the eye, padded outwards (never culls a ray that meets the result)
    bool bounded;             ///< false: the box is infinite (a plane's half-space); nothing is culled
    std::uint32_t root;       ///< into CsgView::nodes
    CsgSlotLayout layout;
    /// A root of two shapes (the common node: a lens, a pipe), combined in closed form
    /// (csg_pair_boundary); other trees by the walk along the line (csg_first_boundary).
    bool pair;
    CsgOp op;  ///< the root's
    /// An object with a shape of several slots (a mesh, whose slots' ends keep triangles; a
    /// torus): its slots are mapped back to shapes by the layout.
    bool multi_slot;
    /// A tree that shows inner surfaces (csg_shows_inner_surfaces: a union not subtracted).
    bool inner_surfaces;
};

/// Every CSG object of a scene (stream/stream_csg.h).
struct CsgView {
    const CsgNode* nodes;          ///< Scene::csg_nodes
    const CsgObjectView* objects;  ///< the objects with a non-empty box
    std::size_t count;
    const KernelObject* records;   ///< shape k's record at k, its flipped one at shapes + k
    std::int32_t first_id;         ///< the id of records[0] in the engine's tables
    std::int32_t shapes;           ///< Scene::csg_shapes.size()
    const Mesh* const* meshes;     ///< per shape: its mesh, or null
    /// Per shape: its box, relative to the eye and padded as the objects' (a packet that
    /// misses it over (0, t_max) takes the shape's span as empty: outside the segment a span
    /// changes no boundary inside it); bounded false: a half-space, never skipped.
    const ObjectBounds* shape_boxes;
    const std::uint8_t* shape_bounded;
    /// The objects' hierarchy (render/csg_hierarchy.h; indices into `objects`), when `tree`:
    /// its nodes (null when no object is bounded), leaf order, and the unbounded objects.
    /// Without it, the objects are tested in a list.
    const accel::WideNode* tree_nodes;
    const std::uint32_t* tree_prims;
    const std::uint32_t* tree_unbounded;
    std::size_t tree_unbounded_count;
    bool tree;
};

/// Closest hit (see ClosestHitFn), through CSG objects; any hit (see AnyHitFn) likewise.
using CsgClosestFn = void (*)(const CsgView& csg, RayView rays, std::int32_t* object);
using CsgAnyFn = void (*)(const CsgView& csg, RayView rays);

}  // namespace streamrt
