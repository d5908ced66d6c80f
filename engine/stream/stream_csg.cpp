#include "stream/stream_csg.h"

#include "render/csg_spans.h"
#include "stream/stream_accel.h"

namespace streamrt {

std::unique_ptr<const StreamCsg> StreamCsg::build_for(const Scene& scene, std::int32_t first_id,
                                                      const glm::dvec3& eye, const accel::AccelConfig& config) {
    if (scene.csg_objects.empty()) return nullptr;
    return std::make_unique<const StreamCsg>(scene, first_id, eye, config);
}

StreamCsg::StreamCsg(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye,
                     const accel::AccelConfig& config)
    : nodes_(scene.csg_nodes), scene_objects_(scene.csg_objects.size()) {
    const auto shapes = std::int32_t(scene.csg_shapes.size());
    std::vector<CsgBox> boxes;  // per view
    for (const CsgObject& o : scene.csg_objects) {
        const CsgBox box = csg_node_box(scene, o.root);
        if (box.empty()) continue;  // children that cannot overlap: nothing to hit
        boxes.push_back(box);
        CsgObjectView v{};
        v.root = o.root;
        v.bounded = box.bounded();
        if (v.bounded) v.box = padded_bounds(box.lo, box.hi, eye);
        v.layout = csg_slot_layout(scene, o);
        const std::uint32_t lo = o.first_shape;
        const CsgNode& root = nodes_[o.root];
        v.op = root.op;
        v.inner_surfaces = csg_shows_inner_surfaces(nodes_.data(), o.root);
        // (children 0 and 1 are its shapes lo and lo + 1, in the kernels' lane arrays)
        v.pair = root.children.size() == 2 && !root.children[0].is_node && !root.children[1].is_node &&
                 root.children[0].index == lo && root.children[1].index == lo + 1;
        v.multi_slot = v.layout.slots() > v.layout.shapes;
        v.pair = v.pair && !v.multi_slot;
        objects_.push_back(v);
    }
    records_.resize(2 * std::size_t(shapes));
    surfaces_.resize(records_.size());
    for (std::int32_t k = 0; k < shapes; ++k) {
        const Object& s = scene.csg_shapes[std::size_t(k)];
        meshes_.push_back(scene.mesh_of(s));
        double lo[3], hi[3];
        const bool bounded = accel::object_world_bounds(s, scene.mesh_of(s), lo, hi);
        shape_boxes_.push_back(bounded ? padded_bounds(lo, hi, eye) : ObjectBounds{});
        shape_bounded_.push_back(bounded ? 1 : 0);
        for (const std::int32_t flip : {0, 1}) {
            const std::size_t at = std::size_t(k + flip * shapes);
            records_[at] = kernel_object(s, scene.mesh_of(s), first_id + std::int32_t(at), eye);
            records_[at].xf.flip = std::uint32_t(flip);
            surfaces_[at] = {{s.color.x, s.color.y, s.color.z}, s.material};
        }
    }
    tree_ = CsgHierarchy::build_for(boxes, config, eye);
    view_ = {.nodes = nodes_.data(),
             .objects = objects_.data(),
             .count = objects_.size(),
             .records = records_.data(),
             .first_id = first_id,
             .shapes = shapes,
             .meshes = meshes_.data(),
             .shape_boxes = shape_boxes_.data(),
             .shape_bounded = shape_bounded_.data(),
             .tree_nodes = tree_ && !tree_->bvh.empty() ? tree_->bvh.nodes.data() : nullptr,
             .tree_prims = tree_ ? tree_->bvh.prim_index.data() : nullptr,
             .tree_unbounded = tree_ ? tree_->unbounded.data() : nullptr,
             .tree_unbounded_count = tree_ ? tree_->unbounded.size() : 0,
             .tree = tree_ != nullptr};
}

}  // namespace streamrt
