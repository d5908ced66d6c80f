#include "stream/stream_scene.h"

#include <algorithm>
#include <cmath>

#include "accel/scene_bvh.h"

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
/// The eye, and the camera-only scene (no objects) that places the camera relative to it.
Scene camera_relative_to_eye(const Scene& scene, glm::dvec3& eye) {
    Scene r;
    r.settings = scene.settings;
    const RenderSettings& s = scene.settings;
    const glm::dmat4 cam = scene.camera.world_from_canonical(s.width, s.height);
    eye = transform_point(cam, {0.0, 0.0, 1.0});
    r.camera.look_at = false;
    r.camera.md = translate_matrix(-eye) * cam;
    return r;
}

void rows3x4(const glm::dmat4& m, float* out) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) out[r * 4 + c] = float(m[c][r]);  // glm is column-major
}
}  // namespace

StreamScene::StreamScene(const Scene& scene) : settings(scene.settings) {
    // Each object is moved as it is converted (no copy of the scene: at 1e6 objects that copy
    // doubled the memory and the set-up time).
    glm::dvec3 eye;
    camera = CameraRays<float>::from(camera_relative_to_eye(scene, eye));
    const glm::dmat4 to_eye = translate_matrix(-eye), from_eye = translate_matrix(eye);
    objects.reserve(scene.objects.size());
    materials.reserve(scene.objects.size());
    const RenderSettings& s = scene.settings;
    background = {float(s.background.x), float(s.background.y), float(s.background.z)};
    bool any_refl = false, any_trans = false;
    std::fill(std::begin(group_bounded), std::end(group_bounded), true);
    for (std::size_t i = 0; i < scene.objects.size(); ++i) {
        const Object& o = scene.objects[i];
        ShadeObject so{};
        so.kind = o.kind;
        so.param = float(o.param());
        if (o.kind == ShapeKind::Mesh && o.mesh) {
            so.mesh = &o.mesh->view();
            meshes.push_back(o.mesh);
            has_meshes = true;
        }
        // Md' = T(-e) Md and Mi' = Mi T(e), in double before rounding (Mi from the exact
        // inverse, not re-inverted); Mn does not see translations.
        rows3x4(o.xf.mi * from_eye, so.mi);
        rows3x4(to_eye * o.xf.md, so.md);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) so.mn[r * 3 + c] = float(o.xf.mn[c][r]);
        objects.push_back(so);
        MaterialT<float> mat = MaterialT<float>::from(o.material);
        const auto period = [&](double e) {  // e / cell modulo 2, in [0, 2)
            const double c = e / o.material.cell;
            return float(c - 2.0 * std::floor(c * 0.5));
        };
        mat.cell_offset = {period(eye.x), period(eye.y), period(eye.z)};
        materials.push_back(mat);
        ObjectXf xf{};
        std::copy(std::begin(so.mi), std::end(so.mi), xf.m);
        xf.param = so.param;
        xf.id = std::int32_t(i);
        xf.mesh = so.mesh;
        groups[int(o.kind)].push_back(xf);
        double lo[3], hi[3];
        ObjectBounds box{};
        if (accel::object_world_bounds(o, lo, hi)) {
            for (int a = 0; a < 3; ++a) {
                lo[a] -= eye[a];
                hi[a] -= eye[a];
                // Padded outwards by a relative margin and a few float ulps of the coordinates,
                // so that the float slab test never culls a packet the shape would hit.
                const double pad = 1e-5 * (hi[a] - lo[a]) + 8.0 * 1.2e-7 * std::max(std::fabs(lo[a]), std::fabs(hi[a]));
                box.lo[a] = std::nextafter(float(lo[a] - pad), -INFINITY);
                box.hi[a] = std::nextafter(float(hi[a] + pad), INFINITY);
            }
        } else {
            group_bounded[int(o.kind)] = false;
        }
        group_bounds[int(o.kind)].push_back(box);
        any_refl |= o.material.refl > 0;
        any_trans |= o.material.trans > 0;
    }
    for (Light l : scene.lights) {
        l.pos -= eye;
        lights.push_back(LightT<float>::from(l));
    }
    features.lighting = s.degree >= 1;
    features.shadows = s.degree >= 5 && !lights.empty();
    features.reflect = s.degree >= 3 && s.depth >= 1 && any_refl;
    features.refract = s.degree >= 4 && s.depth >= 1 && any_trans;
    features.jitter = s.spp > 1;
    accel = StreamAccel::build_for(scene, eye);
}

}  // namespace streamrt
