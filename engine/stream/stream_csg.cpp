#include "stream/stream_csg.h"

#include <limits>

#include "core/transform.h"
#include "mesh/mesh_trace.h"
#include "stream/stream_accel.h"

namespace streamrt {

std::unique_ptr<const StreamCsg> StreamCsg::build_for(const Scene& scene, std::int32_t first_id,
                                                      const glm::dvec3& eye) {
    if (scene.csg_objects.empty()) return nullptr;
    return std::make_unique<const StreamCsg>(scene, first_id, eye);
}

StreamCsg::StreamCsg(const Scene& scene, std::int32_t first_id, const glm::dvec3& eye)
    : nodes_(scene.csg_nodes), first_id_(first_id), shapes_(std::int32_t(scene.csg_shapes.size())) {
    for (const CsgObject& o : scene.csg_objects) {
        roots_.push_back(o.root);
        CsgBox box = csg_node_box(scene, o.root);
        for (int a = 0; a < 3; ++a) box.lo[a] -= eye[a], box.hi[a] -= eye[a];  // infinite ends stay so
        boxes_.push_back(box);
    }
    records_.resize(2 * std::size_t(shapes_));
    surfaces_.resize(records_.size());
    for (std::int32_t k = 0; k < shapes_; ++k) {
        const Object& s = scene.csg_shapes[std::size_t(k)];
        meshes_.push_back(scene.mesh_of(s));
        for (const std::int32_t flip : {0, 1}) {
            const std::size_t at = std::size_t(k + flip * shapes_);
            records_[at] = kernel_object(s, scene.mesh_of(s), first_id + std::int32_t(at), eye);
            records_[at].xf.flip = std::uint32_t(flip);
            surfaces_[at] = {{s.color.x, s.color.y, s.color.z}, s.material};
        }
    }
}

const CsgBoundary<float>* StreamCsg::first_surface(std::size_t k, const Vec3f& o, const Vec3f& d, float t_max,
                                                   CsgSpans<float>& spans) const {
    if (!ray_may_meet(boxes_[k], o, d, 0.f, t_max)) return nullptr;
    // Each shape's span from the ray in its canonical space, as the shade stage will find the
    // hit point there again (the same float Mi, the same evaluation order).
    csg_node_spans(nodes_.data(), roots_[k],
                   [&](std::uint32_t shape, CsgSpans<float>& into) {
                       const ObjectXf& xf = records_[shape].xf;
                       const Vec3f oc = apply_point(xf.m, o), dc = apply_vector(xf.m, d);
                       if (meshes_[shape]) add_mesh_spans(into, *meshes_[shape], oc, dc, shape);
                       else add_solid_span(into, csg_shape_span(ShapeKind(xf.kind), oc, dc, xf.param), shape);
                   },
                   spans);
    return first_boundary(spans, 0.f, t_max);
}

void StreamCsg::closest(RayView rays, std::int32_t* object) const {
    CsgSpans<float> spans;
    for (std::size_t i = 0; i < rays.count; ++i) {
        float t_max = rays.t_max[i];
        if (!(t_max > 0.f)) continue;
        const Vec3f o{rays.ox[i], rays.oy[i], rays.oz[i]}, d{rays.dx[i], rays.dy[i], rays.dz[i]};
        for (std::size_t k = 0; k < roots_.size(); ++k) {
            const CsgBoundary<float>* at = first_surface(k, o, d, t_max, spans);
            if (!at) continue;
            t_max = at->t;
            object[i] = first_id_ + std::int32_t(at->shape) + (at->flip ? shapes_ : 0);
            if (const Mesh* m = meshes_[at->shape]; m && rays.prim) {
                // The crossing's barycentric coordinates: its triangle met again over every t,
                // in the shape's canonical space, as the shade stage reads them.
                const ObjectXf& xf = records_[at->shape].xf;
                const Vec3f oc = apply_point(xf.m, o), dc = apply_vector(xf.m, d);
                const MeshView& v = m->view();
                const float inf = std::numeric_limits<float>::infinity();
                const TriangleHit<float> h = triangle_hit(watertight_ray(oc, dc), mesh_vertex<float>(v, at->tri, 0),
                                                          mesh_vertex<float>(v, at->tri, 1), mesh_vertex<float>(v, at->tri, 2),
                                                          -inf, inf);
                rays.prim[i] = std::int32_t(at->tri);
                rays.bu[i] = h.t < inf ? h.u : 1.f / 3.f;
                rays.bv[i] = h.t < inf ? h.v : 1.f / 3.f;
            }
        }
        rays.t_max[i] = t_max;
    }
}

void StreamCsg::any(RayView rays) const {
    CsgSpans<float> spans;
    for (std::size_t i = 0; i < rays.count; ++i) {
        const float t_max = rays.t_max[i];
        if (!(t_max > 0.f)) continue;
        const Vec3f o{rays.ox[i], rays.oy[i], rays.oz[i]}, d{rays.dx[i], rays.dy[i], rays.dz[i]};
        for (std::size_t k = 0; k < roots_.size(); ++k)
            if (first_surface(k, o, d, t_max, spans)) {
                rays.t_max[i] = 0.f;
                break;
            }
    }
}

}  // namespace streamrt
