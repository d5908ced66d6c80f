#pragma once
// The handout's algorithm as written: scalar, double precision, one ray at a time, closest
// hit over every object, colour gathered recursively by degree. Kept as a first-class
// renderer: it is the reference the stream engine is measured against.
#include <memory>
#include <vector>

#include "scene/scene_bvh.h"

#include "core/vec3.h"
#include "image/framebuffer.h"
#include "parallel/parallelism.h"
#include "render/camera_rays.h"
#include "render/csg_hierarchy.h"
#include "render/csg_spans.h"
#include "render/render_stats.h"
#include "render/sampling.h"
#include "render/shading.h"
#include "mesh/mesh_trace.h"
#include "scene/animation.h"
#include "scene/scene.h"

namespace streamrt {

struct RayD {
    Vec3d origin, dir;  ///< world space; dir is unit for camera, reflected and refracted rays
    double cone = 0;    ///< footprint width at the origin (ray cone), for texture filtering
    ColorT<double> throughput{1, 1, 1};  ///< product of the refl / trans weights from the camera (the cut-off)
};

/// The ray's "memory" of its closest hit (handout): object, distance, point and normal.
struct HitD {
    int object = -1;
    double t = 0;
    Vec3d point;   ///< world space, Md applied to the canonical hit point
    Vec3d normal;  ///< world space, unit, outward (Mn applied to the canonical normal)
    // Where a texture is read (render/texture.h): the canonical point, and for a mesh the
    // triangle and its barycentrics.
    Vec3d canonical;
    std::uint32_t tri = 0;
    double bu = 0, bv = 0;
};

class RecursiveRenderer {
  public:
    /// accel: whether and how the object hierarchy is used (EngineOptions::accel).
    /// `settings`: what is rendered (a render job's, the scene's own otherwise); the scene's
    /// objects are read while rendering, so `scene` must outlive the renderer.
    RecursiveRenderer(const Scene& scene, const RenderSettings& settings, const accel::AccelConfig& accel = {});
    explicit RecursiveRenderer(const Scene& scene, const accel::AccelConfig& accel = {})
        : RecursiveRenderer(scene, scene.settings, accel) {}

    /// Renders the whole image; tiles in parallel, each pixel independent of -j.
    Framebuffer render(Parallelism& par, RenderProgress* progress = nullptr) const;

    /// Colour brought back by one ray (the handout's recursive procedure).
    /// `key`: the camera sample's light-sampling key (render/sampling.h light_key), which
    /// every ray of the sample carries for area lights.
    ColorT<double> trace(const RayD& ray, int depth, RayCounts& counts, std::uint32_t key = 0) const;

    /// Closest hit over all objects (through the scene's hierarchy when it has one), t in (t_min, t_max); false for a miss.
    bool closest_hit(const RayD& ray, double t_min, double t_max, HitD& hit) const;

    /// True if anything lies on the ray for t in (0, t_max) (shadow rays).
    bool occluded(const RayD& ray, double t_max) const;

    /// One pixel's colour: the average over its samples.
    ColorT<double> render_pixel(int x, int y, RayCounts& counts) const;
    /// The colour of camera sample j of `run` (render/sampling.h) in pixel (x, y).
    ColorT<double> render_sample(int x, int y, SampleRun run, int j, RayCounts& counts) const;

    /// Animation: `scene` is the scene at another frame (scene_at_frame: the same objects,
    /// materials and meshes, at other places), read from now on; re-derives what `change`
    /// names only (moved objects' Mi and their boxes, lights, camera).
    void update(const Scene& scene, const FrameChange& change);

  private:
    /// What the loop over objects reads: Mi (world -> canonical, top three rows) computed
    /// once from the scene's Md; Mn is Mi's linear part transposed, applied on the fly.
    struct PreparedObject {
        glm::dmat4x3 mi;
        double param;
        ShapeKind kind;
        const Mesh* mesh;  ///< Mesh only
    };
    /// The texture colour at a hit of a textured material (out of trace's frame).
    ColorT<double> texture_color_at(const MaterialT<double>& material, const RayD& ray, const HitD& hit) const;
    /// A smooth mesh's hit: the shift of its shadow rays' origin (mesh/terminator.h).
    Vec3d terminator_shift_at(const RayD& ray, const HitD& hit) const;
    /// What a closer hit leaves behind: the canonical ray, and for a mesh the triangle and
    /// its barycentric coordinates.
    struct Candidate {
        Vec3d o, d;
        std::uint32_t tri = 0;
        double u = 0, v = 0;
    };
    /// Tests object i in its canonical space; shrinks t_max and records it on a closer hit.
    bool test_object(std::size_t i, const RayD& ray, double t_min, double& t_max, Candidate& c) const;
    /// Tests CSG object k (render/csg_spans.h): the result's first surface in (t_min, t_max)
    /// shrinks t_max; its shape's number in objects_ is returned (-1: none closer), and
    /// `flip` says whether the shape's normal is to be turned round there.
    int test_csg(std::size_t k, const RayD& ray, double t_min, double& t_max, Candidate& c, bool& flip) const;
    /// Object i: one of the scene's objects, or from csg_base_ on one of its CSG shapes.
    const Object& object_at(std::size_t i) const {
        return i < csg_base_ ? scene_->objects[i] : scene_->csg_shapes[i - csg_base_];
    }
    const Scene* scene_;
    RenderSettings settings_;
    accel::AccelConfig accel_config_;
    std::unique_ptr<accel::SceneBvh> bvh_;  ///< null: the handout's loop over all objects
    CameraRays<double> camera_;
    std::vector<PreparedObject> objects_;  ///< the scene's objects, then its CSG shapes
    std::size_t csg_base_ = 0;             ///< the first CSG shape's index in objects_
    std::vector<CsgBox> csg_boxes_;        ///< per CSG object: its result's box (csg_node_box)
    std::vector<CsgSlotLayout> csg_layouts_;  ///< per CSG object: its shapes' slots
    std::vector<std::uint8_t> csg_inner_;      ///< per CSG object: shows inner surfaces (csg_shows_inner_surfaces)
    std::unique_ptr<const CsgHierarchy> csg_tree_;  ///< over the CSG objects' boxes; null: tested in a list
    std::vector<MaterialT<double>> materials_;  ///< per scene material
    std::vector<LightT<double>> lights_;
};

}  // namespace streamrt
