#include "stream/stream_scene.h"

namespace streamrt {

namespace {
void rows3x4(const glm::dmat4& m, float* out) {
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) out[r * 4 + c] = float(m[c][r]);  // glm is column-major
}
}  // namespace

StreamScene::StreamScene(const Scene& scene)
    : settings(scene.settings), camera(CameraRays<float>::from(scene)) {
    const RenderSettings& s = scene.settings;
    background = {float(s.background.x), float(s.background.y), float(s.background.z)};
    bool any_refl = false, any_trans = false;
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
        rows3x4(o.xf.mi, so.mi);
        rows3x4(o.xf.md, so.md);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) so.mn[r * 3 + c] = float(o.xf.mn[c][r]);
        objects.push_back(so);
        materials.push_back(MaterialT<float>::from(o.material));
        ObjectXf xf{};
        std::copy(std::begin(so.mi), std::end(so.mi), xf.m);
        xf.param = so.param;
        xf.id = std::int32_t(i);
        xf.mesh = so.mesh;
        groups[int(o.kind)].push_back(xf);
        any_refl |= o.material.refl > 0;
        any_trans |= o.material.trans > 0;
    }
    for (const Light& l : scene.lights) lights.push_back(LightT<float>::from(l));
    features.lighting = s.degree >= 1;
    features.shadows = s.degree >= 5 && !lights.empty();
    features.reflect = s.degree >= 3 && s.depth >= 1 && any_refl;
    features.refract = s.degree >= 4 && s.depth >= 1 && any_trans;
    features.jitter = s.spp > 1;
    accel = StreamAccel::build_for(scene);
}

}  // namespace streamrt
