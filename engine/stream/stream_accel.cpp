#include "stream/stream_accel.h"

#include <algorithm>
#include <cmath>

#include "core/memory_advice.h"
#include "mesh/mesh.h"
#include "parallel/parallelism.h"

namespace streamrt {

KernelObject kernel_object(const Scene& scene, std::size_t index, std::int32_t id, const glm::dvec3& shift) {
    const Object& o = scene.objects[index];
    return kernel_object(o, scene.mesh_of(o), id, shift);
}

KernelObject kernel_object(const Object& o, const Mesh* mesh, std::int32_t id, const glm::dvec3& shift) {
    // Mi of the object moved by -shift: Mi T(shift), composed in double before rounding.
    glm::dmat4x3 mi = affine_inverse(o.md);
    mi[3] += glm::dmat3(mi) * shift;
    KernelObject k{};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) k.xf.m[r * 4 + c] = float(mi[c][r]);  // glm is column-major
    k.xf.param = float(o.param);
    k.xf.id = std::uint32_t(id);
    k.xf.mesh = mesh ? &mesh->view() : nullptr;
    k.xf.kind = std::uint32_t(o.kind);
    return k;
}

ObjectBounds padded_bounds(const double lo[3], const double hi[3], const glm::dvec3& shift) {
    ObjectBounds box{};
    for (int a = 0; a < 3; ++a) {
        const double l = lo[a] - shift[a], h = hi[a] - shift[a];
        // A relative margin and a few float ulps of the coordinates, so that the float slab
        // test never culls a packet the shape would hit.
        const double pad = 1e-5 * (h - l) + 8.0 * 1.2e-7 * std::max(std::fabs(l), std::fabs(h));
        box.lo[a] = std::nextafter(float(l - pad), -INFINITY);
        box.hi[a] = std::nextafter(float(h + pad), INFINITY);
    }
    return box;
}

std::shared_ptr<StreamAccel> StreamAccel::build_for(const Scene& scene, const accel::AccelConfig& config,
                                                    const glm::dvec3& shift) {
    auto bvh = accel::SceneBvh::build_for(scene, config, shift);
    if (!bvh) return nullptr;
    return std::make_shared<StreamAccel>(scene, std::move(bvh), config, shift);
}

StreamAccel::StreamAccel(const Scene& scene, std::unique_ptr<accel::SceneBvh> bvh, const accel::AccelConfig& config,
                         const glm::dvec3& shift)
    : bvh_(std::move(bvh)), config_(config) {
    // Leaf order: the leaves' ranges [child, child + count) index objects_ directly, so the
    // hierarchy's own map to scene indices moves here (id -> scene index).
    order_ = std::move(bvh_->bvh.prim_index);
    bvh_->bvh.prim_index.clear();
    const std::size_t n_bounded = order_.size();
    order_.insert(order_.end(), bvh_->unbounded.begin(), bvh_->unbounded.end());
    objects_.resize(order_.size());  // unwritten (FillLaterVec): first touched below, in parallel
    want_huge_pages(objects_.data(), objects_.size());
    parallel_for_index(order_.size(), 4096, [&](std::size_t id) {
        objects_[id] = kernel_object(scene, order_[id], std::int32_t(id), shift);
    });
    for (std::size_t id = n_bounded; id < order_.size(); ++id) unbounded_[objects_[id].xf.kind].push_back(objects_[id].xf);
}

void StreamAccel::set_tail(std::span<const KernelObject> tail) {
    objects_.resize(order_.size());
    objects_.insert(objects_.end(), tail.begin(), tail.end());
}

std::size_t StreamAccel::memory_bytes() const {
    return bvh_->bvh.memory_bytes() + objects_.size() * sizeof(KernelObject) + order_.size() * sizeof(std::uint32_t);
}

void StreamAccel::closest(const KernelTable& kt, RayView rays, std::int32_t* object, bool coherent) const {
    for (int k = 0; k < kShapeKindCount; ++k)
        if (!unbounded_[k].empty()) kt.closest[k](rays, object, unbounded_[k].data(), unbounded_[k].size());
    if (bvh_->bvh.empty()) return;
    const AccelKernelTable& at = accel_kernel_table(kt.isa);
    const AccelView view{bvh_->bvh.nodes.data(), objects_.data()};
    const accel::Traversal tr = coherent ? config_.primary : config_.secondary;
    (tr == accel::Traversal::Packet ? at.closest_packet : at.closest_single)(view, rays, object);
}

void StreamAccel::any(const KernelTable& kt, RayView rays) const {
    for (int k = 0; k < kShapeKindCount; ++k)
        if (!unbounded_[k].empty()) kt.any[k](rays, unbounded_[k].data(), unbounded_[k].size());
    if (bvh_->bvh.empty()) return;
    const AccelKernelTable& at = accel_kernel_table(kt.isa);
    const AccelView view{bvh_->bvh.nodes.data(), objects_.data()};
    (config_.shadow == accel::Traversal::Packet ? at.any_packet : at.any_single)(view, rays);
}

// ---- animation: per-frame update ----
bool StreamAccel::update(const Scene& scene, std::span<const std::uint32_t> moved, const glm::dvec3& shift, bool all) {
    if (!all && !bvh_->refit_pays(moved.size(), config_)) return false;
    if (id_of_.empty()) {
        id_of_.assign(scene.objects.size(), -1);
        for (std::size_t id = 0; id < order_.size(); ++id) id_of_[order_[id]] = std::int32_t(id);
    }
    std::vector<std::uint32_t> every;
    if (all) {
        every.resize(scene.objects.size());
        for (std::uint32_t i = 0; i < every.size(); ++i) every[i] = i;
        moved = every;
    }
    parallel_for_index(moved.size(), 4096, [&](std::size_t k) {
        const std::int32_t id = id_of_[moved[k]];
        objects_[std::size_t(id)] = kernel_object(scene, moved[k], id, shift);
    });
    const std::size_t n_bounded = bvh_->bounded;
    bool planes = false;
    for (const std::uint32_t i : moved) planes = planes || std::size_t(id_of_[i]) >= n_bounded;
    if (planes) {
        for (auto& u : unbounded_) u.clear();
        for (std::size_t id = n_bounded; id < order_.size(); ++id)
            unbounded_[objects_[id].xf.kind].push_back(objects_[id].xf);
    }
    bvh_->refit(scene, moved, std::span<const std::uint32_t>(order_.data(), n_bounded), shift);
    return true;
}

}  // namespace streamrt
