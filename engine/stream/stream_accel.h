#pragma once
// The stream engine's side of the object hierarchy (engine/accel): the scene's SceneBvh with
// its leaf objects laid out for the traversal kernels, the unbounded objects (planes) kept
// for the flat per-kind kernels, and the choice of traversal per ray class. The intersect and
// occlusion stages call closest()/any() instead of their per-kind loops when a scene has one.
#include <cstdint>
#include <memory>
#include <vector>

#include "accel/scene_bvh.h"
#include "kernels/accel_kernel_table.h"
#include "kernels/kernel_table.h"
#include "stream/ray_stream.h"

namespace streamrt {

class StreamAccel {
  public:
    /// nullptr when the scene is traced without the hierarchy (accel_config()).
    /// For the scene translated by -shift (the stream engine renders relative to the eye).
    static std::shared_ptr<const StreamAccel> build_for(const Scene& scene, const glm::dvec3& shift = glm::dvec3(0.0));
    StreamAccel(const Scene& scene, std::unique_ptr<accel::SceneBvh> bvh, const glm::dvec3& shift = glm::dvec3(0.0));

    /// Closest hit of every ray (see ClosestHitFn); `coherent` picks the configured traversal
    /// for primary rays, otherwise for secondary rays.
    void closest(const KernelTable& kt, RayView rays, std::int32_t* object, bool coherent) const;
    /// Any hit for shadow rays (see AnyHitFn).
    void any(const KernelTable& kt, RayView rays) const;

    const accel::SceneBvh& scene_bvh() const { return *bvh_; }
    std::size_t memory_bytes() const;

  private:
    std::unique_ptr<accel::SceneBvh> bvh_;
    std::vector<AccelObject> prims_;                ///< leaf order
    std::vector<ObjectXf> unbounded_[kShapeKindCount];  ///< per kind, outside the hierarchy
    accel::Traversal primary_, secondary_, shadow_;
};

}  // namespace streamrt
