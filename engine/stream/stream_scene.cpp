#include "stream/stream_scene.h"

#include <algorithm>
#include <cmath>

#include "scene/scene_bvh.h"
#include "core/memory_advice.h"
#include "parallel/parallelism.h"

namespace streamrt {

namespace {

/// The scene moved so that the camera's eye is at the origin (camera-relative rendering).
/// The stream engine works in float; world coordinates of 1e6 keep only ~0.06 units of
/// resolution, so a scene placed 1e6 units away lost its contact shadows and got holes and
/// acne. Every float the engine sees (rays, hit points, light positions) is now relative to
/// the eye and as small as the scene itself, whatever its placement. The translation is
/// applied in double: Md' = T(-e) Md and Mi' = Mi T(e) (from the exact Mi, not re-inverted).
/// The checker pattern needs world positions: MaterialT::cell_offset carries e / cell,
/// reduced modulo the pattern's period of 2 cells (exactly, in double).
/// The eye, and the camera placed relative to it, for an image of these settings.
Camera camera_relative_to_eye(const Camera& camera, const RenderSettings& s, glm::dvec3& eye) {
    Camera r;
    const glm::dmat4 cam = camera.world_from_canonical(s.width, s.height);
    eye = transform_point(cam, {0.0, 0.0, 1.0});
    r.look_at = false;
    r.md = translate_matrix(-eye) * cam;
    r.aperture = camera.aperture;
    r.focus = camera.focus_distance(cam);  // resolved: the default depends on the form
    return r;
}

/// The checker's cell_offset of material m for an engine origin at `eye`: e / cell modulo
/// the pattern's period of 2 cells, in [0, 2).
glm::vec3 cell_offset(const Material& m, const glm::dvec3& eye) {
    const auto period = [&](double e) {
        const double c = e / m.cell;
        return float(c - 2.0 * std::floor(c * 0.5));
    };
    return {period(eye.x), period(eye.y), period(eye.z)};
}

}  // namespace

StreamScene::StreamScene(const Scene& scene, const RenderSettings& render_settings,
                         const accel::AccelConfig& accel_config)
    : settings(render_settings), accel_config_(accel_config) {
    scene.check_object_count();  // a scene made in code (the Python module) is checked here
    // Objects are moved as they are converted (no copy of the scene: at 1e6 objects that copy
    // doubled the memory and the set-up time).
    glm::dvec3 eye;
    camera = CameraRays<float>::from(camera_relative_to_eye(scene.camera, settings, eye), settings);
    eye_ = eye;
    const RenderSettings& s = settings;
    background = {float(s.background.x), float(s.background.y), float(s.background.z)};
    meshes = scene.meshes;
    textures = scene.textures;
    has_meshes = !meshes.empty();
    mesh_hybrid_lanes = has_meshes ? accel_config_.mesh_hybrid_lanes : 0;

    accel = StreamAccel::build_for(scene, accel_config_, eye);
    const std::size_t n = scene.objects.size();
    std::fill(std::begin(group_bounded), std::end(group_bounded), true);
    if (!accel) convert_flat(scene);
    csg = StreamCsg::build_for(scene, std::int32_t(n), eye, accel_config_);
    link_objects(n);
    fill_surfaces(scene);

    bool any_refl = false, any_trans = false, any_fresnel = false, any_diff = false;
    for (const Material& m : scene.materials) {
        MaterialT<float> mat = MaterialT<float>::from(m);
        const glm::vec3 offset = cell_offset(m, eye);
        mat.cell_offset = {offset.x, offset.y, offset.z};
        if (m.texture >= 0) {
            mat.texture = scene.textures[std::size_t(m.texture)]->view();
            features.textures = true;
        }
        materials.push_back(mat);
        any_refl |= m.refl > 0;
        any_trans |= m.trans > 0;
        any_fresnel |= mat.fresnel;  // reflects even with refl = 0 (at degree >= 4)
        any_diff |= m.diff > 0;
    }
    convert_lights(scene);
    features.lighting = s.degree >= 1;
    features.shadows = s.degree >= 5 && !lights.empty();
    features.reflect = s.degree >= 3 && s.depth >= 1 && (any_refl || (s.degree >= 4 && any_fresnel));
    features.refract = s.degree >= 4 && s.depth >= 1 && any_trans;
    features.jitter = s.spp > 1;
    features.lens = camera.has_lens();
    for (const LightT<float>& l : lights) {
        shadow_rays_per_hit += std::size_t(l.samples);
        if (l.area) features.area_samples += l.samples;
    }
    features.area_lights = features.lighting && features.area_samples > 0;
    features.bounce = s.degree >= 6 && s.depth >= 1 && any_diff;
    features.keys = features.area_lights || features.bounce;
}

void StreamScene::fill_surfaces(const Scene& scene) {
    const std::size_t n = scene.objects.size();
    surfaces.resize(object_count);
    want_huge_pages(surfaces.data(), object_count);
    parallel_for_index(n, 4096, [&](std::size_t id) {
        const Object& o = scene.objects[accel ? accel->scene_index(std::int32_t(id)) : id];
        surfaces[id] = {{o.color.x, o.color.y, o.color.z}, o.material};
    });
    if (csg) std::copy(csg->surfaces().begin(), csg->surfaces().end(), surfaces.begin() + std::ptrdiff_t(n));
}

void StreamScene::link_objects(std::size_t scene_objects) {
    object_count = scene_objects + (csg ? csg->records().size() : 0);
    if (accel) {
        if (csg) accel->set_tail(csg->records());
        objects = accel->objects().data();
        return;
    }
    flat_objects_.resize(scene_objects);
    if (csg) flat_objects_.insert(flat_objects_.end(), csg->records().begin(), csg->records().end());
    objects = flat_objects_.data();
}

void StreamScene::convert_lights(const Scene& scene) {
    lights.clear();
    for (const Light& given : scene.lights) {
        Light l = rendered_light(given, settings);
        l.pos -= eye_;
        lights.push_back(LightT<float>::from(l));
    }
}

void StreamScene::convert_flat(const Scene& scene) {
    // The handout's loop over every object, per kind, with a box per object for culling.
    const glm::dvec3 eye = eye_;
    const std::size_t n = scene.objects.size();
    std::fill(std::begin(group_bounded), std::end(group_bounded), true);
    for (int k = 0; k < kShapeKindCount; ++k) groups[k].clear(), group_bounds[k].clear();
    {
        flat_objects_.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const Object& o = scene.objects[i];
            flat_objects_[i] = kernel_object(scene, i, std::int32_t(i), eye);
            groups[int(o.kind)].push_back(flat_objects_[i].xf);
            double lo[3], hi[3];
            ObjectBounds box{};
            if (accel::object_world_bounds(o, scene.mesh_of(o), lo, hi)) {
                box = padded_bounds(lo, hi, eye);
            } else {
                group_bounded[int(o.kind)] = false;
            }
            group_bounds[int(o.kind)].push_back(box);
        }
    }
}

// ---- animation: per-frame update ----
void StreamScene::update(const Scene& scene, const FrameChange& change) {
    glm::dvec3 eye = eye_;
    if (change.camera) camera = CameraRays<float>::from(camera_relative_to_eye(scene.camera, settings, eye), settings);
    const bool shifted = eye != eye_;
    eye_ = eye;
    if (change.lights || shifted) convert_lights(scene);
    if (shifted)
        for (std::size_t m = 0; m < materials.size(); ++m) {
            const glm::vec3 offset = cell_offset(scene.materials[m], eye);
            materials[m].cell_offset = {offset.x, offset.y, offset.z};
        }
    if (!shifted && change.objects.empty() && change.csg.empty()) return;
    // CSG records follow the eye and a keyed block: rebuilt whole (a few per object).
    if ((shifted || !change.csg.empty()) && csg) csg = StreamCsg::build_for(scene, std::int32_t(scene.objects.size()), eye, accel_config_);
    if (!accel) {
        convert_flat(scene);  // O(N): few objects, unless --accel flat forces the flat loops
        link_objects(scene.objects.size());
    } else if (!accel->update(scene, change.objects, eye, shifted)) {
        accel = StreamAccel::build_for(scene, accel_config_, eye);
        link_objects(scene.objects.size());
        fill_surfaces(scene);  // ids follow the new leaf order
    } else {
        link_objects(scene.objects.size());  // the CSG records follow the eye
    }
}

}  // namespace streamrt
