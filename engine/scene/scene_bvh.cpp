#include "scene/scene_bvh.h"

#include <algorithm>
#include <cmath>

#include "mesh/mesh.h"
#include "shapes/shapes.h"

#include "parallel/parallelism.h"

namespace streamrt::accel {

bool object_world_bounds(const Object& o, const Mesh* mesh, double lo[3], double hi[3]) {
    const glm::dmat4x3& m = o.md;
    // The canonical box: the shape's own bounds (shapes/shapes.h), or the mesh's.
    double c[3], e[3];
    if (o.kind == ShapeKind::Mesh) {
        if (!mesh || mesh->triangle_count() == 0) return false;
        for (int a = 0; a < 3; ++a) c[a] = 0.5 * (mesh->lo[a] + mesh->hi[a]), e[a] = 0.5 * (mesh->hi[a] - mesh->lo[a]);
    } else {
        const CanonicalBounds b = canonical_bounds(o.kind, o.param);
        switch (b.form) {
            case CanonicalBounds::Form::Unbounded: return false;
            case CanonicalBounds::Form::UnitBall:
                // Exact box of an affine image of the unit ball: centre +- the row norms of M.
                for (int a = 0; a < 3; ++a) {
                    const double r = std::sqrt(m[0][a] * m[0][a] + m[1][a] * m[1][a] + m[2][a] * m[2][a]);
                    lo[a] = m[3][a] - r;
                    hi[a] = m[3][a] + r;
                }
                return true;
            case CanonicalBounds::Form::Box: break;
        }
        for (int a = 0; a < 3; ++a) c[a] = 0.5 * (b.lo[a] + b.hi[a]), e[a] = 0.5 * (b.hi[a] - b.lo[a]);
    }
    // The canonical box through Md: centre +- |M| half-extent (the box of the 8 corners).
    for (int a = 0; a < 3; ++a) {
        double mid = m[3][a], ext = 0;
        for (int k = 0; k < 3; ++k) {
            mid += m[k][a] * c[k];
            ext += std::abs(m[k][a]) * e[k];
        }
        lo[a] = mid - ext;
        hi[a] = mid + ext;
    }
    return true;
}

std::unique_ptr<SceneBvh> SceneBvh::build(const Scene& scene, const BuildOptions& options, const glm::dvec3& shift) {
    auto s = std::make_unique<SceneBvh>();
    const std::size_t n = scene.objects.size();
    // Unbounded objects keep an empty box, which the build leaves out; its prim_index then
    // names scene objects directly.
    std::vector<Aabb> boxes(n);
    parallel_for_index(n, 4096, [&](std::size_t i) {
        double lo[3], hi[3];
        if (!object_world_bounds(scene.objects[i], scene.mesh_of(scene.objects[i]), lo, hi)) return;
        for (int a = 0; a < 3; ++a) lo[a] -= shift[a], hi[a] -= shift[a];
        boxes[i] = conservative_box(lo, hi);
    });
    for (std::size_t i = 0; i < n; ++i)
        if (boxes[i].empty()) s->unbounded.push_back(std::uint32_t(i));
    s->bounded = n - s->unbounded.size();
    // A mesh in a leaf costs a walk of its own tree for every packet that reaches the leaf, so
    // with meshes every object gets a leaf (its box tested with its siblings' in one wide
    // node): 6 - 9 % less intersect and occlusion time on instanced meshes (docs/performance.md,
    // "Instances").
    BuildOptions opt = options;
    if (std::any_of(scene.objects.begin(), scene.objects.end(), [](const Object& o) { return o.kind == ShapeKind::Mesh; }))
        opt.max_leaf = 1;
    s->bvh = Bvh::build(std::move(boxes), opt);
    return s;
}

std::unique_ptr<SceneBvh> SceneBvh::build_for(const Scene& scene, const AccelConfig& config,
                                              const glm::dvec3& shift) {
    if (config.mode == AccelMode::Flat) return nullptr;
    if (config.mode == AccelMode::Auto) {
        std::size_t bounded = 0;
        for (const Object& o : scene.objects)
            bounded += o.kind == ShapeKind::Mesh || canonical_bounds(o.kind, o.param).bounded();
        if (bounded < config.min_objects) return nullptr;
    }
    return build(scene, config.build, shift);
}

bool SceneBvh::refit_pays(std::size_t moved, const AccelConfig& config) const {
    // Counted over every refit since the build: a tree refitted frame after frame degrades
    // however few objects move each time, so it is rebuilt once enough have moved in all.
    return double(refitted_ + moved) <= config.refit_max_share * double(bounded);
}

void SceneBvh::refit(const Scene& scene, std::span<const std::uint32_t> moved, std::span<const std::uint32_t> order,
                     const glm::dvec3& shift) {
    if (!links_) {
        links_ = std::make_unique<BvhLinks>(bvh, order.size());
        position_.assign(scene.objects.size(), ~0u);
        for (std::size_t p = 0; p < order.size(); ++p) position_[order[p]] = std::uint32_t(p);
    }
    refitted_ += moved.size();
    std::vector<std::uint32_t> positions;
    positions.reserve(moved.size());
    for (const std::uint32_t i : moved)
        if (position_[i] != ~0u && links_->leaf_node[position_[i]] >= 0) positions.push_back(position_[i]);
    accel::refit(bvh, *links_, positions, [&](std::uint32_t p) {
        const Object& o = scene.objects[order[p]];
        double lo[3], hi[3];
        if (!object_world_bounds(o, scene.mesh_of(o), lo, hi)) return Aabb{};
        for (int a = 0; a < 3; ++a) lo[a] -= shift[a], hi[a] -= shift[a];
        return conservative_box(lo, hi);
    });
}

}  // namespace streamrt::accel
