#include "baseline/recursive_renderer.h"

#include <limits>

#include "render/sampling.h"
#include "shapes/shapes.h"
#include "shapes/triangle_math.h"

namespace streamrt {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
inline Vec3d apply_point(const glm::dmat4x3& m, const Vec3d& p) { return to_vec(m * glm::dvec4(to_glm(p), 1.0)); }
inline Vec3d apply_vector(const glm::dmat4x3& m, const Vec3d& v) { return to_vec(m * glm::dvec4(to_glm(v), 0.0)); }
}  // namespace

RecursiveRenderer::RecursiveRenderer(const Scene& scene)
    : scene_(scene), bvh_(accel::SceneBvh::build_for(scene)), camera_(CameraRays<double>::from(scene)) {
    objects_.resize(scene.objects.size());
    parallel_for_index(scene.objects.size(), 4096, [&](std::size_t i) {
        const Object& o = scene.objects[i];
        objects_[i] = {affine_inverse(o.md), o.param, o.kind, scene.mesh_of(o)};
    });
    for (const Material& m : scene.materials) materials_.push_back(MaterialT<double>::from(m));
    for (const Light& l : scene.lights) lights_.push_back(LightT<double>::from(l));
}

bool RecursiveRenderer::test_object(std::size_t i, const RayD& ray, double t_min, double& t_max,
                                    Candidate& c) const {
    const PreparedObject& ob = objects_[i];
    const Vec3d oc = apply_point(ob.mi, ray.origin);
    const Vec3d dc = apply_vector(ob.mi, ray.dir);
    if (ob.kind == ShapeKind::Mesh) {
        if (!ob.mesh) return false;
        // The mesh's own hierarchy, walked in its canonical space (t is the world ray's t).
        const double start = t_max;
        if (mesh_closest(ob.mesh->view(), ob.mesh->bvh, oc, dc, t_min, t_max, c.tri, c.u, c.v) && t_max < start) {
            c.o = oc;
            c.d = dc;
            return true;
        }
        return false;
    }
    const double t = visit_shape(ob.kind, [&](auto shape) {
        return shape.template hit_t<double>(oc, dc, ob.param, t_min, t_max);
    });
    if (!(t < t_max)) return false;
    t_max = t;
    c.o = oc;
    c.d = dc;
    return true;
}

bool RecursiveRenderer::closest_hit(const RayD& ray, double t_min, double t_max, HitD& hit) const {
    // The handout: intersect in each object's canonical space, [Mi A, Mi u). The direction is
    // not renormalised there, so t means the same distance along the world ray for every
    // object and the closest hit is a plain comparison of t.
    int best = -1;
    double best_t = t_max;
    Candidate cand;
    if (bvh_) {
        for (std::uint32_t i : bvh_->unbounded)
            if (test_object(i, ray, t_min, best_t, cand)) best = int(i);
        const accel::Bvh& h = bvh_->bvh;
        accel::traverse_closest<double>(h, ray.origin, ray.dir, best_t,
                                        [&](std::uint32_t first, std::uint32_t count, double& tm) {
                                            for (std::uint32_t k = first; k < first + count; ++k)
                                                if (test_object(h.prim_index[k], ray, t_min, tm, cand))
                                                    best = int(h.prim_index[k]);
                                        });
    } else {
        for (std::size_t i = 0; i < objects_.size(); ++i)
            if (test_object(i, ray, t_min, best_t, cand)) best = int(i);
    }
    if (best < 0) return false;
    const PreparedObject& ob = objects_[std::size_t(best)];
    const Vec3d pc = cand.o + cand.d * best_t;
    const Vec3d nc = ob.kind == ShapeKind::Mesh
                         ? mesh_normal<double>(ob.mesh->view(), cand.tri, cand.u, cand.v, ob.param != 0.0)
                         : visit_shape(ob.kind, [&](auto shape) { return shape.template normal<double>(pc, ob.param); });
    hit.object = best;
    hit.t = best_t;
    hit.point = apply_point(scene_.objects[std::size_t(best)].md, pc);
    hit.normal = to_vec(transform_normal(ob.mi, to_glm(nc)));
    return true;
}

bool RecursiveRenderer::occluded(const RayD& ray, double t_max) const {
    Candidate o;
    // Meshes answer with an any-hit walk of their own hierarchy.
    const auto blocks = [&](std::size_t i, double tm) {
        const PreparedObject& ob = objects_[i];
        if (ob.kind != ShapeKind::Mesh) return test_object(i, ray, 0.0, tm, o);
        if (!ob.mesh) return false;
        return mesh_any(ob.mesh->view(), ob.mesh->bvh, apply_point(ob.mi, ray.origin), apply_vector(ob.mi, ray.dir),
                        0.0, tm);
    };
    if (bvh_) {
        for (std::uint32_t i : bvh_->unbounded) {
            if (blocks(i, t_max)) return true;
        }
        const accel::Bvh& h = bvh_->bvh;
        return accel::traverse_any<double>(h, ray.origin, ray.dir, t_max,
                                           [&](std::uint32_t first, std::uint32_t count, double tm) {
                                               for (std::uint32_t k = first; k < first + count; ++k)
                                                   if (blocks(h.prim_index[k], tm)) return true;
                                               return false;
                                           });
    }
    for (std::size_t i = 0; i < objects_.size(); ++i)
        if (blocks(i, t_max)) return true;
    return false;
}

ColorT<double> RecursiveRenderer::trace(const RayD& ray, int depth, RayCounts& counts) const {
    const RenderSettings& s = scene_.settings;
    HitD hit;
    if (!closest_hit(ray, 0.0, kInf, hit)) return {s.background.x, s.background.y, s.background.z};

    const Object& object = scene_.objects[std::size_t(hit.object)];
    const MaterialT<double>& m = materials_[object.material];
    const ColorT<double> object_color{object.color.x, object.color.y, object.color.z};
    const Vec3d n_out = hit.normal;
    const double cone = ray.cone + camera_.spread * hit.t;
    const ColorT<double> base = surface_color(m, object_color, hit.point, n_out,
                                              footprint_width(ray.cone, camera_.spread, hit.t, dot(ray.dir, n_out)));
    if (s.degree == 0) return base;

    // Light on the side the ray arrives from (a camera inside a room or a sphere sees the
    // inner faces lit).
    const Vec3d n = dot(n_out, ray.dir) < 0 ? n_out : -n_out;
    ColorT<double> color = ambient_light(s.degree, s.ambient, m, base);
    for (const LightT<double>& l : lights_) {
        const LightSample<double> ls = sample_light(l, hit.point);
        const DirectLight<double> dl = direct_light(s.degree, m, base, n, ray.dir, l, ls);
        if (!dl.lit) continue;
        const ColorT<double>& c = dl.color;
        if (s.degree >= 5) {
            const Vec3d from = offset_ray_origin(hit.point, n, ray.origin);
            const Vec3d to = l.kind == LightKind::Directional ? ls.to_light : l.pos - from;
            ++counts.shadow;
            if (occluded({from, to}, ls.t_max)) continue;
        }
        color = color + c;
    }
    if (depth >= s.depth) return color;

    if (s.degree >= 3 && m.refl > 0) {
        const Vec3d r = reflect(ray.dir, n);
        ++counts.reflected;
        color = color + trace({offset_ray_origin(hit.point, n, ray.origin), r, cone}, depth + 1, counts) * m.refl;
    }
    if (s.degree >= 4 && m.trans > 0) {
        const Vec3d t = refract(ray.dir, n_out, m.ior);
        const Vec3d side = dot(t, n_out) > 0 ? n_out : -n_out;
        ++counts.refracted;
        color = color + trace({offset_ray_origin(hit.point, side, ray.origin), t, cone}, depth + 1, counts) * m.trans;
    }
    return color;
}

ColorT<double> RecursiveRenderer::render_pixel(int x, int y, RayCounts& counts) const {
    const RenderSettings& s = scene_.settings;
    const CameraRays<double>& cam = camera_;
    const std::uint64_t pixel = std::uint64_t(y) * std::uint64_t(s.width) + std::uint64_t(x);
    ColorT<double> sum{0, 0, 0};
    for (int k = 0; k < s.spp; ++k) {
        const PixelSample ps = pixel_sample(s.pattern, s.spp, pixel, k);
        const RayD ray{cam.origin, cam.direction(x + ps.x, y + ps.y), 0.0};
        ++counts.primary;
        sum = sum + trace(ray, 0, counts);
    }
    return sum * (1.0 / s.spp);
}

Framebuffer RecursiveRenderer::render(Parallelism& par, RenderProgress* progress) const {
    const RenderSettings& s = scene_.settings;
    Framebuffer fb = Framebuffer::uninitialized(s.width, s.height);  // every tile writes its pixels
    par.for_each_tile(s.width, s.height, kTileSize, [&](int, Tile tile) {
        if (progress && progress->cancelled()) return;
        RayCounts counts;
        for (int y = tile.y0; y < tile.y1; ++y)
            for (int x = tile.x0; x < tile.x1; ++x) {
                if (progress && progress->cancelled()) return;  // seen within one pixel
                const ColorT<double> c = render_pixel(x, y, counts);
                float* px = fb.pixel(x, y);
                px[0] = float(c.x);
                px[1] = float(c.y);
                px[2] = float(c.z);
            }
        if (progress) progress->add(counts);
    });
    return fb;
}

}  // namespace streamrt
