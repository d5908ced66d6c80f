#pragma once
// The stream engine's CSG objects (docs/architecture.md, "CSG"): an object kind of their own,
// built only for a scene with `csg` blocks (StreamScene::csg is null otherwise, and no stage
// runs anything of it). The intersect and occlusion stages test them after the other objects
// (the hierarchy or the flat kernels), in a short list, each culled per packet by its
// result's box (csg_node_box), with the SIMD kernels of kernels/csg_kernel.h. The shade stage
// reads their shapes' records by id like any object's.
#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/csg_view.h"
#include "render/csg_hierarchy.h"
#include "kernels/kernel_object.h"
#include "kernels/kernel_table.h"
#include "kernels/ray_stream.h"
#include "scene/scene.h"

namespace streamrt {

class StreamCsg {
  public:
    /// Null for a scene without CSG. `first_id`: the id of the first CSG shape's record (the
    /// scene objects' count); the engine's origin is at `eye` (camera-relative rendering);
    /// `config` decides whether the objects get their hierarchy (CsgHierarchy::build_for).
    static std::unique_ptr<const StreamCsg> build_for(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye,
                                                      const accel::AccelConfig& config);
    StreamCsg(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye, const accel::AccelConfig& config);
    StreamCsg(const StreamCsg&) = delete;  // view() points into the members
    StreamCsg& operator=(const StreamCsg&) = delete;

    /// Every CSG shape's record twice, in id order: shape k (Scene::csg_shapes) at first_id + k,
    /// and at first_id + n + k with `flip` set, for the hits where its surface bounds the
    /// result from the shape's outside (a subtracted shape's: the normal is turned round).
    const std::vector<KernelObject>& records() const { return records_; }
    /// Colour and material of each record, in the same order.
    const std::vector<SurfaceRecord>& surfaces() const { return surfaces_; }
    /// The scene's CSG objects.
    std::size_t object_count() const { return scene_objects_; }
    /// What the kernels read (the objects whose result is not empty).
    const CsgView& view() const { return view_; }

    /// Closest hit: a ray whose first surface of a CSG result in (0, t_max) comes before its
    /// hit so far gets that t in t_max and the surface's record id in object[].
    void closest(const KernelTable& kt, RayView rays, std::int32_t* object) const { kt.csg_closest(view_, rays, object); }
    /// Any hit (shadow rays): t_max = 0 for a ray blocked by a CSG result (not by a removed
    /// part); rays blocked already (t_max <= 0) are skipped.
    void any(const KernelTable& kt, RayView rays) const { kt.csg_any(view_, rays); }

  private:
    std::vector<CsgNode> nodes_;           ///< Scene::csg_nodes
    std::vector<CsgObjectView> objects_;   ///< the objects whose result is not empty
    std::vector<KernelObject> records_;
    std::vector<SurfaceRecord> surfaces_;
    std::vector<const Mesh*> meshes_;  ///< per CSG shape: its mesh, or null (held by the scene's meshes)
    std::vector<ObjectBounds> shape_boxes_;     ///< per CSG shape (CsgView::shape_boxes)
    std::vector<std::uint8_t> shape_bounded_;
    std::unique_ptr<const CsgHierarchy> tree_;  ///< over objects_, relative to the eye; null: a list
    std::size_t scene_objects_ = 0;
    CsgView view_{};
};

}  // namespace streamrt
