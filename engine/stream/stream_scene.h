#pragma once
// The scene as the stream engine reads it: single precision, flat tables, objects grouped
// by shape kind so that each kernel runs over one kind's objects only.
#include <cstdint>
#include <memory>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh/mesh.h"
#include "render/camera_rays.h"
#include "render/shading.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "stream/stream_accel.h"
#include "stream/stream_csg.h"

namespace streamrt {

/// The features a scene uses; the pipeline is specialised on them at compile time, so a
/// scene without lights or mirrors runs no code for them.
struct StreamFeatures {
    bool lighting = false;  ///< degree >= 1
    bool shadows = false;   ///< degree >= 5 and at least one light
    bool reflect = false;   ///< degree >= 3, depth >= 1 and some material has refl > 0
    bool refract = false;   ///< degree >= 4, depth >= 1 and some material has trans > 0
    bool jitter = false;    ///< spp > 1
    bool lens = false;      ///< camera aperture > 0: the thin-lens generate kernel
    bool textures = false;  ///< some material has a texture (only those materials read it)
    /// Area lights (with shadows): rays carry light-sampling keys, and each hit sends
    /// area_samples shadow rays for them through the occlusion stage.
    bool area_lights = false;
    int area_samples = 0;
    /// Degree 6, depth >= 1 and some material has diff > 0: diffuse bounces (spawn(diffuse)).
    bool bounce = false;
    /// Rays carry keys (RayStream::key): area lights, or diffuse bounces.
    bool keys = false;
};

struct StreamScene {
    RenderSettings settings;
    StreamFeatures features;
    CameraRays<float> camera;  ///< everything below is relative to the eye (stream_scene.cpp)
    /// Every object as the kernels and the shade stage read it, by id (the ids the intersect
    /// stage writes): the hierarchy's leaf order when there is one, scene order otherwise.
    const KernelObject* objects = nullptr;
    std::size_t object_count = 0;
    FillLaterVec<SurfaceRecord> surfaces;     ///< by id: colour and material index
    std::vector<MaterialT<float>> materials;  ///< by scene material index
    std::vector<LightT<float>> lights;
    /// The most shadow rays one hit sends: one per light, `samples` per area light.
    std::size_t shadow_rays_per_hit = 0;
    /// Without a hierarchy: per shape kind (indexed by ShapeKind), the objects of that kind;
    /// empty kinds get no kernel call at all.
    std::vector<ObjectXf> groups[kShapeKindCount];
    /// World bounds per object of each group, for the per-packet culling of the flat kernels;
    /// a kind with an unbounded member (the plane) is tested without culling.
    std::vector<ObjectBounds> group_bounds[kShapeKindCount];
    bool group_bounded[kShapeKindCount];  ///< set in the constructor
    ColorT<float> background;
    /// The object hierarchy, when the scene is traced with one (stream/stream_accel.h); the
    /// intersect and occlusion stages then use it instead of `groups`, and it owns `objects`.
    std::shared_ptr<StreamAccel> accel;
    /// The CSG objects (stream/stream_csg.h), null in a scene without them; their shapes'
    /// records follow the scene objects' in `objects` and `surfaces` (counted in object_count).
    std::shared_ptr<const StreamCsg> csg;
    /// The meshes the objects use (kept alive here: the objects' records point into them).
    std::vector<std::shared_ptr<const Mesh>> meshes;
    bool has_meshes = false;
    /// AccelConfig::mesh_hybrid_lanes (0 without meshes).
    std::uint32_t mesh_hybrid_lanes = 0;
    /// The images the materials' textures point into (kept alive here).
    std::vector<std::shared_ptr<const Texture>> textures;

    /// accel: whether and how the object hierarchy is used (EngineOptions::accel).
    /// `settings` are what is rendered (a render job's; the scene's own in the second form).
    /// Nothing here points into `scene` afterwards: the tables are converted, and the meshes
    /// and images are held through their shared pointers.
    StreamScene(const Scene& scene, const RenderSettings& settings, const accel::AccelConfig& accel = {});
    explicit StreamScene(const Scene& scene, const accel::AccelConfig& accel = {})
        : StreamScene(scene, scene.settings, accel) {}

    /// Animation (scene/animation.h): `scene` is the scene at another frame (the same objects
    /// at other places); brings the tables up to it, converting only what `change` names (all
    /// objects when the eye moved).
    void update(const Scene& scene, const FrameChange& change);
    StreamScene(const StreamScene&) = delete;  // `objects` may point into flat_objects_
    StreamScene& operator=(const StreamScene&) = delete;

  private:
    std::vector<KernelObject> flat_objects_;  ///< `objects` without a hierarchy
    accel::AccelConfig accel_config_;          ///< kept for rebuilding the hierarchy in update()
    glm::dvec3 eye_{0.0};                     ///< the world position of the engine's origin
    void convert_flat(const Scene& scene);    ///< fills flat_objects_, groups and their bounds
    void convert_lights(const Scene& scene);
    void fill_surfaces(const Scene& scene);   ///< by id: colour and material
    /// Points `objects` at the records (the hierarchy's or flat_objects_) with the CSG shapes'
    /// after them, and sets object_count.
    void link_objects(std::size_t scene_objects);
};

}  // namespace streamrt
