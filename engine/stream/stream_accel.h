#pragma once
// The stream engine's side of the object hierarchy (engine/accel): the scene's SceneBvh with
// every object laid out as the kernels and the shade stage read it, in leaf order (objects
// close in space are close in memory, which is what the shade stage needs at 1e6 objects),
// the unbounded objects (planes) after them and also kept per kind for the flat kernels, and
// the choice of traversal per ray class. The intersect and occlusion stages call
// closest()/any() instead of their per-kind loops when a scene has one.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "scene/scene_bvh.h"
#include "core/default_init.h"
#include "kernels/accel_kernel_table.h"
#include "kernels/kernel_table.h"
#include "kernels/ray_stream.h"

namespace streamrt {

/// The stream engine's record of scene object `index`, moved by -shift (the engine renders
/// relative to the eye), with id `id` in the engine's tables.
KernelObject kernel_object(const Scene& scene, std::size_t index, std::int32_t id, const glm::dvec3& shift);
/// The same for object `o` (a scene object or a CSG shape) and its mesh (null but for meshes).
KernelObject kernel_object(const Object& o, const Mesh* mesh, std::int32_t id, const glm::dvec3& shift);
/// The world box [lo, hi] moved by -shift, in float, padded outwards for the kernels' per-packet
/// culling (ObjectBounds).
ObjectBounds padded_bounds(const double lo[3], const double hi[3], const glm::dvec3& shift);

class StreamAccel {
  public:
    /// nullptr when `config` says the scene is traced without the hierarchy.
    /// For the scene translated by -shift (the stream engine renders relative to the eye).
    static std::shared_ptr<StreamAccel> build_for(const Scene& scene, const accel::AccelConfig& config,
                                                  const glm::dvec3& shift = glm::dvec3(0.0));
    StreamAccel(const Scene& scene, std::unique_ptr<accel::SceneBvh> bvh, const accel::AccelConfig& config,
                const glm::dvec3& shift = glm::dvec3(0.0));

    /// Closest hit of every ray (see ClosestHitFn); `coherent` picks the configured traversal
    /// for primary rays, otherwise for secondary rays. Ids index objects().
    void closest(const KernelTable& kt, RayView rays, std::int32_t* object, bool coherent) const;
    /// Any hit for shadow rays (see AnyHitFn).
    void any(const KernelTable& kt, RayView rays) const;

    /// Every object, bounded ones in leaf order then the unbounded ones, then the tail's; ids
    /// index it.
    const FillLaterVec<KernelObject>& objects() const { return objects_; }
    /// Records the walk never meets, kept after the scene's so that one array holds every
    /// record the shade stage reads by id: a scene's CSG shapes (stream/stream_csg.h), whose
    /// ids follow the scene objects'. Replaces the tail set before; objects() may move.
    void set_tail(std::span<const KernelObject> tail);
    /// The scene index of the object with id `id`.
    std::uint32_t scene_index(std::int32_t id) const { return order_[std::size_t(id)]; }
    const std::vector<std::uint32_t>& scene_order() const { return order_; }

    const accel::SceneBvh& scene_bvh() const { return *bvh_; }
    std::size_t memory_bytes() const;

    /// Animation: the scene objects `moved` (scene indices) have a new Md, and the engine's
    /// origin is now -shift. Rewrites their records and refits the hierarchy over them, and
    /// returns true; false (nothing done) when so many moved that the caller should build a
    /// new StreamAccel instead (SceneBvh::refit_pays). `all`: every object moved (the eye
    /// moved), refitted whatever their number (a translation of everything keeps the tree's
    /// quality).
    bool update(const Scene& scene, std::span<const std::uint32_t> moved, const glm::dvec3& shift, bool all);

  private:
    std::unique_ptr<accel::SceneBvh> bvh_;
    FillLaterVec<KernelObject> objects_;                ///< by id: leaf order, then unbounded
    std::vector<std::uint32_t> order_;                  ///< id -> scene index
    std::vector<ObjectXf> unbounded_[kShapeKindCount];  ///< per kind, outside the hierarchy
    accel::AccelConfig config_;  ///< traversal per ray class, refit or rebuild
    std::vector<std::int32_t> id_of_;  ///< scene index -> id; built on the first update
};

}  // namespace streamrt
