#include "stream/stream_csg.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "render/csg_spans.h"
#include "stream/stream_accel.h"

namespace streamrt {

namespace {

/// The smallest and largest shape number under node `node`.
void shape_range(const std::vector<CsgNode>& nodes, std::uint32_t node, std::uint32_t& lo, std::uint32_t& hi) {
    for (const CsgNode::Child& c : nodes[node].children) {
        if (c.is_node) {
            shape_range(nodes, c.index, lo, hi);
        } else {
            lo = std::min(lo, c.index);
            hi = std::max(hi, c.index);
        }
    }
}

}  // namespace

std::unique_ptr<const StreamCsg> StreamCsg::build_for(const Scene& scene, std::int32_t first_id,
                                                      const glm::dvec3& eye) {
    if (scene.csg_objects.empty()) return nullptr;
    return std::make_unique<const StreamCsg>(scene, first_id, eye);
}

StreamCsg::StreamCsg(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye)
    : nodes_(scene.csg_nodes), scene_objects_(scene.csg_objects.size()) {
    const auto shapes = std::int32_t(scene.csg_shapes.size());
    for (const CsgObject& o : scene.csg_objects) {
        const CsgBox box = csg_node_box(scene, o.root);
        if (box.empty()) continue;  // children that cannot overlap: nothing to hit
        CsgObjectView v{};
        v.root = o.root;
        v.bounded = box.bounded();
        if (v.bounded) v.box = padded_bounds(box.lo, box.hi, eye);
        std::uint32_t lo = std::numeric_limits<std::uint32_t>::max(), hi = 0;
        shape_range(nodes_, o.root, lo, hi);
        v.first_shape = lo;
        v.shape_count = hi - lo + 1;
        // The reader numbers an object's shapes one after the other (at most kMaxCsgShapes):
        // the kernels' per-lane arrays are indexed by shape - first_shape.
        if (v.shape_count > std::uint32_t(kMaxCsgShapes))
            throw std::logic_error("a csg object's shapes are not numbered consecutively");
        const CsgNode& root = nodes_[o.root];
        v.op = root.op;
        // (children 0 and 1 are its shapes first_shape and first_shape + 1, in the kernels' arrays)
        v.pair = root.children.size() == 2 && !root.children[0].is_node && !root.children[1].is_node &&
                 root.children[0].index == lo && root.children[1].index == lo + 1;
        objects_.push_back(v);
    }
    records_.resize(2 * std::size_t(shapes));
    surfaces_.resize(records_.size());
    for (std::int32_t k = 0; k < shapes; ++k) {
        const Object& s = scene.csg_shapes[std::size_t(k)];
        for (const std::int32_t flip : {0, 1}) {
            const std::size_t at = std::size_t(k + flip * shapes);
            records_[at] = kernel_object(s, scene.mesh_of(s), first_id + std::int32_t(at), eye);
            records_[at].xf.flip = std::uint32_t(flip);
            surfaces_[at] = {{s.color.x, s.color.y, s.color.z}, s.material};
        }
    }
    view_ = {.nodes = nodes_.data(),
             .objects = objects_.data(),
             .count = objects_.size(),
             .records = records_.data(),
             .first_id = first_id,
             .shapes = shapes};
}

}  // namespace streamrt
