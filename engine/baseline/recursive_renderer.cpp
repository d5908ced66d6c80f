#include "baseline/recursive_renderer.h"

#include <limits>
#include <tuple>
#include <utility>

#include "mesh/terminator.h"
#include "render/sampling.h"
#include "render/texture.h"
#include "shapes/shapes.h"
#include "shapes/triangle_math.h"

namespace streamrt {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Where shade_hit's results go in the recursive engine: shadow rays are answered at once,
/// children traced at once and their colour brought back times their weight.
struct RecursiveSink {
    static constexpr bool kTestsShadowsNow = true;
    const RecursiveRenderer& renderer;
    int depth;
    RayCounts& counts;
    std::uint32_t key;  ///< the ray's key: its camera sample's light-sampling key, or at degree 6 its own
    bool rekey;         ///< degree 6: children take keys of their own (child_key)
    ColorT<double> color{0, 0, 0};

    std::uint32_t light_key() const { return key; }

    void local(const ColorT<double>& c) { color = c; }
    bool occluded(const Vec3d& from, const Vec3d& to, double t_max) {
        ++counts.shadow;
        return renderer.occluded({from, to}, t_max);
    }
    void child(bool send, const Vec3d& from, const Vec3d& dir, const ColorT<double>& weight,
               const ColorT<double>& throughput, double cone, RayKind kind) {
        if (!send) return;
        ++counts.children(kind);
        const std::uint32_t k = rekey ? child_key(key, std::uint32_t(kind)) : key;
        color = color + mul(renderer.trace({from, dir, cone, throughput}, depth + 1, counts, k), weight);
    }
};
}  // namespace

RecursiveRenderer::RecursiveRenderer(const Scene& scene, const RenderSettings& settings, const accel::AccelConfig& accel)
    : scene_(&scene),
      settings_(settings),
      accel_config_(accel),
      bvh_(accel::SceneBvh::build_for(scene, accel_config_)),
      camera_(CameraRays<double>::from(scene.camera, settings_)) {
    csg_base_ = scene.objects.size();
    objects_.resize(csg_base_ + scene.csg_shapes.size());
    parallel_for_index(objects_.size(), 4096, [&](std::size_t i) {
        const Object& o = object_at(i);
        objects_[i] = {affine_inverse(o.md), o.param, o.kind, scene.mesh_of(o)};
    });
    for (const CsgObject& o : scene.csg_objects) {
        csg_boxes_.push_back(csg_node_box(scene, o.root));
        csg_layouts_.push_back(csg_slot_layout(scene, o));
        csg_inner_.push_back(csg_shows_inner_surfaces(scene.csg_nodes.data(), o.root) ? 1 : 0);
    }
    csg_tree_ = CsgHierarchy::build_for(csg_boxes_, accel_config_);
    for (const Material& m : scene.materials) {
        materials_.push_back(MaterialT<double>::from(m));
        if (m.texture >= 0) materials_.back().texture = scene.textures[std::size_t(m.texture)]->view();
    }
    for (const Light& l : scene.lights) lights_.push_back(LightT<double>::from(rendered_light(l, settings_)));
}

bool RecursiveRenderer::test_object(std::size_t i, const RayD& ray, double t_min, double& t_max,
                                    Candidate& c) const {
    const PreparedObject& ob = objects_[i];
    const Vec3d oc = apply_point(RowsOf{ob.mi}, ray.origin);
    const Vec3d dc = apply_vector(RowsOf{ob.mi}, ray.dir);
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

int RecursiveRenderer::test_csg(std::size_t k, const RayD& ray, double t_min, double& t_max, Candidate& c,
                                bool& flip) const {
    if (!ray_may_meet(csg_boxes_[k], ray.origin, ray.dir, t_min, t_max)) return -1;
    const auto canonical_ray = [&](std::uint32_t shape) {
        const PreparedObject& ob = objects_[csg_base_ + shape];
        return std::pair{apply_point(RowsOf{ob.mi}, ray.origin), apply_vector(RowsOf{ob.mi}, ray.dir)};
    };
    // Each slot's span (a mesh's several), then the walk along the line (render/csg_spans.h).
    const CsgSlotLayout& layout = csg_layouts_[k];
    CsgLine<double> line;
    std::array<CsgSlotEnds, kMaxCsgShapes> ends;  // csg_scalar_line fills what the walk reads
    std::array<std::uint8_t, kMaxCsgShapes> live;
    const int live_count = csg_scalar_line(
        layout, canonical_ray,
        [&](std::uint32_t shape) {
            const PreparedObject& ob = objects_[csg_base_ + shape];
            return std::tuple{ob.kind, ob.param, ob.kind == ShapeKind::Mesh ? ob.mesh : nullptr};
        },
        line, ends.data(), live.data());
    const CsgFirst<double> at = csg_first_boundary(scene_->csg_nodes.data(), scene_->csg_objects[k].root, layout,
                                                   line, live.data(), live_count, t_min, t_max, csg_inner_[k] != 0);
    if (!(at.t < t_max)) return -1;
    t_max = at.t;
    const auto slot = std::size_t(at.slot);
    const std::uint32_t shape = layout.first_shape + layout.shape_of[slot];
    std::tie(c.o, c.d) = canonical_ray(shape);
    flip = csg_flip(at.at_exit, at.entering, ends[slot].turned[at.at_exit ? 1 : 0]);
    if (objects_[csg_base_ + shape].kind == ShapeKind::Mesh) {
        // For the normal and the texture.
        c.tri = ends[slot].tri[at.at_exit ? 1 : 0];
        mesh_crossing_uv(objects_[csg_base_ + shape].mesh->view(), c.tri, c.o, c.d, c.u, c.v);
    }
    return int(csg_base_ + shape);
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
        for (std::size_t i = 0; i < csg_base_; ++i)
            if (test_object(i, ray, t_min, best_t, cand)) best = int(i);
    }
    // CSG objects after the others, with the closest hit so far: through their own hierarchy
    // (render/csg_hierarchy.h) or in a list, each culled by its result's box.
    bool flip = false;
    const auto csg = [&](std::size_t k, double& tm) {
        bool flip_k = false;
        if (const int i = test_csg(k, ray, t_min, tm, cand, flip_k); i >= 0) {
            best = i;
            flip = flip_k;
        }
    };
    if (csg_tree_) {
        for (const std::uint32_t k : csg_tree_->unbounded) csg(k, best_t);
        const accel::Bvh& h = csg_tree_->bvh;
        accel::traverse_closest<double>(h, ray.origin, ray.dir, best_t,
                                        [&](std::uint32_t first, std::uint32_t count, double& tm) {
                                            for (std::uint32_t k = first; k < first + count; ++k)
                                                csg(h.prim_index[k], tm);
                                        });
    } else {
        for (std::size_t k = 0; k < scene_->csg_objects.size(); ++k) csg(k, best_t);
    }
    if (best < 0) return false;
    const PreparedObject& ob = objects_[std::size_t(best)];
    const Vec3d pc = cand.o + cand.d * best_t;
    const Vec3d nc = ob.kind == ShapeKind::Mesh
                         ? mesh_normal<double>(ob.mesh->view(), cand.tri, cand.u, cand.v, ob.param != 0.0)
                         : visit_shape(ob.kind, [&](auto shape) { return shape.template normal<double>(pc, ob.param); });
    hit.object = best;
    hit.t = best_t;
    hit.point = apply_point(RowsOf{object_at(std::size_t(best)).md}, pc);
    hit.normal = apply_normal(RowsOf{ob.mi}, flip ? -nc : nc);
    hit.canonical = pc;
    hit.tri = cand.tri;
    hit.bu = cand.u;
    hit.bv = cand.v;
    return true;
}

bool RecursiveRenderer::occluded(const RayD& ray, double t_max) const {
    Candidate o;
    // Meshes answer with an any-hit walk of their own hierarchy.
    const auto blocks = [&](std::size_t i, double tm) {
        const PreparedObject& ob = objects_[i];
        if (ob.kind != ShapeKind::Mesh) return test_object(i, ray, 0.0, tm, o);
        if (!ob.mesh) return false;
        return mesh_any(ob.mesh->view(), ob.mesh->bvh, apply_point(RowsOf{ob.mi}, ray.origin),
                        apply_vector(RowsOf{ob.mi}, ray.dir), 0.0, tm);
    };
    const auto csg_blocks = [&](std::size_t k, double tm) {
        bool flip = false;
        return test_csg(k, ray, 0.0, tm, o, flip) >= 0;
    };
    if (csg_tree_) {
        for (const std::uint32_t k : csg_tree_->unbounded)
            if (csg_blocks(k, t_max)) return true;
        const accel::Bvh& h = csg_tree_->bvh;
        const auto leaf = [&](std::uint32_t first, std::uint32_t count, double tm) {
            for (std::uint32_t k = first; k < first + count; ++k)
                if (csg_blocks(h.prim_index[k], tm)) return true;
            return false;
        };
        if (accel::traverse_any<double>(h, ray.origin, ray.dir, t_max, leaf)) return true;
    } else {
        for (std::size_t k = 0; k < scene_->csg_objects.size(); ++k)
            if (csg_blocks(k, t_max)) return true;
    }
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
    for (std::size_t i = 0; i < csg_base_; ++i)
        if (blocks(i, t_max)) return true;
    return false;
}

// Out of line: the lookup's locals stay out of trace's frame, which recurses once per bounce.
[[gnu::noinline]] ColorT<double> RecursiveRenderer::texture_color_at(const MaterialT<double>& material, const RayD& ray,
                                                                   const HitD& hit) const {
    const PreparedObject& ob = objects_[std::size_t(hit.object)];
    const double footprint = footprint_width(ray.cone, camera_.spread, hit.t, dot(ray.dir, hit.normal));
    const double scale = canonical_per_world<double>(RowsOf{ob.mi});
    return ob.kind == ShapeKind::Mesh
               ? mesh_texture_color(material, ob.mesh->view(), hit.tri, hit.bu, hit.bv, scale, footprint)
               : texture_color(material, ob.kind, hit.canonical, ob.param, scale, footprint);
}

// Out of line, like texture_color_at: the corners stay out of trace's frame.
[[gnu::noinline]] Vec3d RecursiveRenderer::terminator_shift_at(const RayD& ray, const HitD& hit) const {
    const PreparedObject& ob = objects_[std::size_t(hit.object)];
    return terminator_shift(RowsOf{ob.mi}, smooth_corners<double>(ob.mesh->view(), hit.tri), hit.bu, hit.bv,
                            meets_outside(hit.normal, ray.dir));
}

ColorT<double> RecursiveRenderer::trace(const RayD& ray, int depth, RayCounts& counts, std::uint32_t key) const {
    const RenderSettings& s = settings_;
    HitD hit;
    if (!closest_hit(ray, 0.0, kInf, hit)) return {s.background.x, s.background.y, s.background.z};

    const Object& object = object_at(std::size_t(hit.object));
    const ShadeRules<double> rules{
        .degree = s.degree,
        .ambient = s.ambient,
        .spawn = depth < s.depth,
        .cutoff = s.degree >= 6 ? 0.0 : s.cutoff,  // biased: degree 6 ends paths by roulette instead
        .spread = camera_.spread,
        .eye = camera_.origin,  // offsets measured from the eye, as the stream engine's
        .roulette = depth >= kRouletteFromDepth,
        .sequence_bits = first_bounce_bits(s, depth)};
    // Weight 1: the caller multiplies what this ray brings back by its weight.
    const ArrivingRay<double> arriving{ray.origin, ray.dir, hit.t, ray.cone, {1, 1, 1}, ray.throughput};
    const MaterialT<double>& material = materials_[object.material];
    // The texture, or a mesh's vertex colours, replace the object's colour (render/texture.h).
    const PreparedObject& ob = objects_[std::size_t(hit.object)];
    const ColorT<double> object_color =
        material.texture ? texture_color_at(material, ray, hit)
        : material.vertex_colors && ob.mesh && ob.mesh->view().vertex_colors
            ? mesh_vertex_color(ob.mesh->view(), hit.tri, hit.bu, hit.bv)
            : ColorT<double>{object.color.x, object.color.y, object.color.z};
    RecursiveSink sink{*this, depth, counts, key, s.degree >= 6};
    // A smooth mesh's shadow rays start from its curved patch, not the flat triangle.
    const bool smooth = ob.kind == ShapeKind::Mesh && ob.param != 0.0;
    const auto shadow_point = [&](const Vec3d& p) { return smooth ? p + terminator_shift_at(ray, hit) : p; };
    const auto shade = [&]<bool kLit, bool kShadows, bool kBounce>() {
        shade_hit<kLit, kShadows, true, true, kBounce>(rules, material, lights_.data(), lights_.size(), arriving,
                                                       hit.point, hit.normal, object_color, true, sink, shadow_point);
    };
    if (s.degree == 0) shade.template operator()<false, false, false>();
    else if (s.degree < 5) shade.template operator()<true, false, false>();
    else if (s.degree == 5) shade.template operator()<true, true, false>();
    else shade.template operator()<true, true, true>();
    return sink.color;
}

ColorT<double> RecursiveRenderer::render_sample(int x, int y, SampleRun run, int j, RayCounts& counts) const {
    const RenderSettings& s = settings_;
    const CameraRays<double>& cam = camera_;
    const std::uint64_t pixel = sample_key(run, x, y, s.width);
    const PixelSample ps = pixel_sample(s.pattern, run, pixel, j);
    RayD ray{cam.origin, {}, 0.0};
    if (cam.has_lens()) {  // thin lens: the sample's point on the lens (render/sampling.h)
        const PixelSample ls = lens_sample(s.pattern, run, pixel, j);
        cam.lens_ray(double(x + ps.x), double(y + ps.y), double(ls.x), double(ls.y), ray.origin, ray.dir);
    } else {
        ray.dir = cam.direction(double(x + ps.x), double(y + ps.y));
    }
    ++counts.primary;
    return trace(ray, 0, counts, camera_key(s.degree, s.spp, pixel, run.first + j));
}

ColorT<double> RecursiveRenderer::render_pixel(int x, int y, RayCounts& counts) const {
    const int spp = settings_.spp;
    ColorT<double> sum{0, 0, 0};
    for (int k = 0; k < spp; ++k) sum = sum + render_sample(x, y, SampleRun{0, spp}, k, counts);
    return sum * (1.0 / spp);
}

Framebuffer RecursiveRenderer::render(Parallelism& par, RenderProgress* progress) const {
    const RenderSettings& s = settings_;
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

// ---- animation: per-frame update ----
void RecursiveRenderer::update(const Scene& scene, const FrameChange& change) {
    scene_ = &scene;
    for (const std::uint32_t i : change.objects) objects_[i].mi = affine_inverse(scene.objects[i].md);
    for (const std::uint32_t k : change.csg) {
        const CsgObject& o = scene.csg_objects[k];
        for (std::uint32_t s = o.first_shape; s < o.first_shape + o.shape_count; ++s)
            objects_[csg_base_ + s].mi = affine_inverse(scene.csg_shapes[s].md);
        csg_boxes_[k] = csg_node_box(scene, o.root);
    }
    if (!change.csg.empty()) csg_tree_ = CsgHierarchy::build_for(csg_boxes_, accel_config_);  // a few boxes: rebuilt
    if (change.lights) {
        lights_.clear();
        for (const Light& l : scene.lights) lights_.push_back(LightT<double>::from(rendered_light(l, settings_)));
    }
    if (change.camera) camera_ = CameraRays<double>::from(scene.camera, settings_);
    if (bvh_ && !change.objects.empty()) {
        if (bvh_->refit_pays(change.objects.size(), accel_config_))
            bvh_->refit(scene, change.objects, bvh_->bvh.prim_index);
        else bvh_ = accel::SceneBvh::build(scene, accel_config_.build);
    }
}

}  // namespace streamrt
