#pragma once
// The hierarchy over a scene's CSG objects (docs/architecture.md, "CSG"), shared by both
// engines: each object bounded by its result's box (csg_node_box: an intersection by its
// children's overlap, a difference by its first child's), so that a ray tests the objects
// whose results it may meet instead of every one. The same 8-wide tree as the objects' (accel/bvh.h),
// walked after it with the ray's closest hit so far.
#include <cstdint>
#include <memory>
#include <vector>

#include "accel/bvh.h"
#include "render/csg_spans.h"
#include "scene/scene_bvh.h"

namespace streamrt {

struct CsgHierarchy {
    accel::Bvh bvh;                        ///< prim_index: the caller's object numbers
    std::vector<std::uint32_t> unbounded;  ///< objects with an infinite box (a half-space's), tested always

    /// Over the objects of `boxes` (the caller's numbering), moved by -shift: null when the
    /// configuration traces flat, or (AccelMode::Auto) when fewer than config.min_objects
    /// objects are bounded, where a list is as fast. An empty box (children that cannot
    /// overlap) is in neither part: nothing can hit it.
    static std::unique_ptr<const CsgHierarchy> build_for(const std::vector<CsgBox>& boxes,
                                                         const accel::AccelConfig& config,
                                                         const glm::dvec3& shift = glm::dvec3(0.0)) {
        if (config.mode == accel::AccelMode::Flat) return nullptr;
        std::size_t bounded = 0;
        for (const CsgBox& b : boxes) bounded += !b.empty() && b.bounded() ? 1 : 0;
        if (config.mode == accel::AccelMode::Auto && bounded < config.min_objects) return nullptr;
        auto h = std::make_unique<CsgHierarchy>();
        std::vector<accel::Aabb> aabbs(boxes.size());  // empty ones are left out of the build
        for (std::size_t k = 0; k < boxes.size(); ++k) {
            const CsgBox& b = boxes[k];
            if (b.empty()) continue;
            if (!b.bounded()) {
                h->unbounded.push_back(std::uint32_t(k));
                continue;
            }
            double lo[3], hi[3];
            for (int a = 0; a < 3; ++a) lo[a] = b.lo[a] - shift[a], hi[a] = b.hi[a] - shift[a];
            aabbs[k] = accel::conservative_box(lo, hi);
        }
        h->bvh = accel::Bvh::build(std::move(aabbs), config.build);
        return h;
    }
};

}  // namespace streamrt
