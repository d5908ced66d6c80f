#include "stream/stream_accel.h"

#include "mesh/mesh.h"

namespace streamrt {

namespace {
void rows3x4(const glm::dmat4& m, float* out) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) out[r * 4 + c] = float(m[c][r]);  // glm is column-major
}
ObjectXf object_xf(const Object& o, std::uint32_t id, const glm::dvec3& shift) {
    ObjectXf xf{};
    rows3x4(o.xf.mi * translate_matrix(shift), xf.m);  // Mi of the object moved by -shift
    xf.param = float(o.param());
    xf.id = std::int32_t(id);
    xf.mesh = o.mesh ? &o.mesh->view() : nullptr;
    return xf;
}
}  // namespace

std::shared_ptr<const StreamAccel> StreamAccel::build_for(const Scene& scene, const glm::dvec3& shift) {
    auto bvh = accel::SceneBvh::build_for(scene, accel::accel_config(), shift);
    if (!bvh) return nullptr;
    return std::make_shared<const StreamAccel>(scene, std::move(bvh), shift);
}

StreamAccel::StreamAccel(const Scene& scene, std::unique_ptr<accel::SceneBvh> bvh, const glm::dvec3& shift)
    : bvh_(std::move(bvh)) {
    const accel::AccelConfig& c = accel::accel_config();
    primary_ = c.primary;
    secondary_ = c.secondary;
    shadow_ = c.shadow;
    prims_.reserve(bvh_->bvh.prim_index.size());
    for (std::uint32_t id : bvh_->bvh.prim_index)
        prims_.push_back({object_xf(scene.objects[id], id, shift), std::uint32_t(scene.objects[id].kind)});
    for (std::uint32_t id : bvh_->unbounded)
        unbounded_[int(scene.objects[id].kind)].push_back(object_xf(scene.objects[id], id, shift));
}

std::size_t StreamAccel::memory_bytes() const {
    return bvh_->bvh.memory_bytes() + prims_.size() * sizeof(AccelObject);
}

void StreamAccel::closest(const KernelTable& kt, RayView rays, std::int32_t* object, bool coherent) const {
    for (int k = 0; k < kShapeKindCount; ++k)
        if (!unbounded_[k].empty()) kt.closest[k](rays, object, unbounded_[k].data(), unbounded_[k].size());
    if (bvh_->bvh.empty()) return;
    const AccelKernelTable& at = accel_kernel_table(kt.isa);
    const AccelView view{bvh_->bvh.nodes.data(), prims_.data()};
    const accel::Traversal tr = coherent ? primary_ : secondary_;
    (tr == accel::Traversal::Packet ? at.closest_packet : at.closest_single)(view, rays, object);
}

void StreamAccel::any(const KernelTable& kt, RayView rays) const {
    for (int k = 0; k < kShapeKindCount; ++k)
        if (!unbounded_[k].empty()) kt.any[k](rays, unbounded_[k].data(), unbounded_[k].size());
    if (bvh_->bvh.empty()) return;
    const AccelKernelTable& at = accel_kernel_table(kt.isa);
    const AccelView view{bvh_->bvh.nodes.data(), prims_.data()};
    (shadow_ == accel::Traversal::Packet ? at.any_packet : at.any_single)(view, rays);
}

}  // namespace streamrt
