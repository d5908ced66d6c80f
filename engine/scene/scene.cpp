#include "scene/scene.h"

#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>

namespace streamrt {

Display display_of(const RenderSettings& s) {
    Display d;
    d.calibration = s.calibration;
    d.colorspace = s.colorspace;
    d.tonemap = s.tonemap;
    d.exposure = float(s.exposure);
    d.exr = s.exr;
    return d;
}


glm::dmat4 Camera::world_from_canonical(int width, int height) const {
    if (!look_at) return md;
    // Homothety (rx, ry, df) with df = 1: the screen's half-height is tan(fov/2) at unit
    // distance from the eye; then a rotation taking -z to the view direction and +y to up,
    // then a translation putting the canonical eye (0,0,1) on `eye`.
    const double ry = std::tan(fov * std::numbers::pi / 360.0);
    const double rx = ry * double(width) / double(height);
    const glm::dvec3 forward = glm::normalize(look - eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
    const glm::dvec3 true_up = glm::cross(right, forward);
    glm::dmat4 rot(1.0);
    rot[0] = glm::dvec4(right, 0.0);
    rot[1] = glm::dvec4(true_up, 0.0);
    rot[2] = glm::dvec4(-forward, 0.0);
    const double df = 1.0;
    const glm::dmat4 m = translate_matrix(eye - df * (-forward)) * rot * scale_matrix({rx, ry, df});
    return m;
}

double Camera::focus_distance(const glm::dmat4& md) const {
    if (focus > 0.0) return focus;
    if (look_at) return glm::length(look - eye);
    return glm::length(glm::dvec3(md[2]));
}

}  // namespace streamrt

namespace streamrt {

std::uint32_t Scene::intern_material(const Material& m) {
    const auto [it, added] = material_index_.try_emplace(m, std::uint32_t(materials.size()));
    if (added) materials.push_back(m);
    return it->second;
}

void Scene::check_object_count(std::size_t limit) const {
    if (objects.size() <= limit) return;
    const std::string msg = "the scene holds " + std::to_string(objects.size()) + " objects, more than the " +
                            std::to_string(limit) + " streamrt supports; this is object " + std::to_string(limit + 1);
    if (limit < object_locs.size() && object_locs[limit].file < files.size()) throw SceneError(where(limit), msg);
    throw SceneError(SourceLoc{path.empty() ? std::string("<scene>") : path, 0, 0}, msg);
}

bool same_file(const std::string& a, const std::string& b) {
    struct stat sa {}, sb {};
    const bool a_exists = ::stat(a.c_str(), &sa) == 0, b_exists = ::stat(b.c_str(), &sb) == 0;
    if (a_exists && b_exists) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (a_exists != b_exists) return false;
    std::error_code ea, eb;
    const auto ca = std::filesystem::weakly_canonical(a, ea), cb = std::filesystem::weakly_canonical(b, eb);
    return !ea && !eb && ca == cb;
}

const SceneInput* Scene::input_at(const std::string& out) const {
    for (const SceneInput& in : inputs)
        if (same_file(out, in.path)) return &in;
    return nullptr;
}

void Scene::add_object(Object o, const Material& m, const ObjectLoc& loc) {
    o.material = intern_material(m);
    objects.push_back(o);
    object_locs.push_back(loc);
}

}  // namespace streamrt
