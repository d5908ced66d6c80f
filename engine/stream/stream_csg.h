#pragma once
// The stream engine's CSG objects (docs/architecture.md, "CSG"): an object kind of their own,
// built only for a scene with `csg` blocks (StreamScene::csg is null otherwise, and no stage
// runs anything of it). The intersect and occlusion stages test them after the other objects
// (the hierarchy or the flat kernels), in a short list, each culled by its result's box
// (csg_node_box). The shade stage reads their shapes' records by id like any object's.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/vec3.h"
#include "kernels/kernel_object.h"
#include "kernels/ray_stream.h"
#include "render/csg_spans.h"
#include "scene/scene.h"

namespace streamrt {

class StreamCsg {
  public:
    /// Null for a scene without CSG. `first_id`: the id of the first CSG shape's record (the
    /// scene objects' count); the engine's origin is at `eye` (camera-relative rendering).
    static std::unique_ptr<const StreamCsg> build_for(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye);
    StreamCsg(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye);

    /// Every CSG shape's record twice, in id order: shape k (Scene::csg_shapes) at first_id + k,
    /// and at first_id + n + k with `flip` set, for the hits where its surface bounds the
    /// result from the shape's outside (a subtracted shape's: the normal is turned round).
    const std::vector<KernelObject>& records() const { return records_; }
    /// Colour and material of each record, in the same order.
    const std::vector<SurfaceRecord>& surfaces() const { return surfaces_; }
    std::size_t object_count() const { return roots_.size(); }

    /// Closest hit: a ray whose first surface of a CSG result in (0, t_max) comes before its
    /// hit so far gets that t in t_max and the surface's record id in object[] (on a mesh, its
    /// triangle and barycentric coordinates in prim, bu, bv). Lane by lane, in float
    /// (render/csg_spans.h with V = float).
    void closest(RayView rays, std::int32_t* object) const;
    /// Any hit (shadow rays): t_max = 0 for a ray blocked by a CSG result (not by a removed
    /// part); rays blocked already (t_max <= 0) are skipped.
    void any(RayView rays) const;

  private:
    /// CSG object k's first surface along o + t d with 0 < t < t_max, or null; `spans` holds
    /// the object's spans (fixed arrays: nothing is allocated per ray).
    const CsgBoundary<float>* first_surface(std::size_t k, const Vec3f& o, const Vec3f& d, float t_max,
                                            CsgSpans<float>& spans) const;

    std::vector<CsgNode> nodes_;        ///< Scene::csg_nodes
    std::vector<std::uint32_t> roots_;  ///< per CSG object, its root node
    std::vector<CsgBox> boxes_;         ///< per CSG object, its result's box, relative to the eye
    std::vector<KernelObject> records_;
    std::vector<SurfaceRecord> surfaces_;
    std::vector<const Mesh*> meshes_;   ///< per CSG shape: its mesh, or null (held by the scene's meshes)
    std::int32_t first_id_ = 0;
    std::int32_t shapes_ = 0;  ///< Scene::csg_shapes.size(): the flipped records' offset
};

}  // namespace streamrt
