#pragma once
// The parser's contract, checked by the fuzz target on every input and by the regression
// test on every saved input. Each function returns "" when the contract holds, otherwise
// what is broken.
//  - The only exception parse_scene() throws is SceneError, whose text is
//    "FILE:LINE:COL: message" on one line with no control characters.
//  - A scene that parses is fully valid: settings in their documented ranges, every
//    transform finite and invertible with finite Mi and Mn, light directions unit length,
//    a camera transform that is finite and invertible for the scene's image size, and a
//    memory estimate that neither overflows nor throws anything but a one-line UsageError.
#include <cmath>
#include <string>

#include "driver/limits.h"
#include "scene/parser.h"
#include "shapes/shapes.h"

namespace streamrt_fuzz {

using namespace streamrt;

inline bool finite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}
inline bool finite(const glm::dmat3& m) {
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}
inline bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

inline std::string check_error(const SceneError& e) {
    const std::string what = e.what();
    for (unsigned char c : what)
        if (c < 0x20 || c == 0x7f) return "message has a control character: " + what;
    const SourceLoc& at = e.where();
    if (at.line < 1 || at.column < 1) return "error without line:col: " + what;
    if (what.rfind(at.str() + ": ", 0) != 0) return "message does not start with file:line:col: " + what;
    if (e.message().empty()) return "empty message: " + what;
    return "";
}

inline std::string check_scene(const Scene& sc) {
    const RenderSettings& s = sc.settings;
    if (s.width < 1 || s.width > 32768 || s.height < 1 || s.height > 32768) return "image size out of range";
    if (s.spp < 1 || s.spp > 65536 || s.depth < 0 || s.depth > 256 || s.degree < 0 || s.degree > 6)
        return "spp, depth or degree out of range";
    if (!(s.ambient >= 0 && s.ambient <= 1) || !finite(s.background) || s.output.empty())
        return "ambient, background or output invalid";
    if (!(s.exposure >= 1e-6 && s.exposure <= 1e6)) return "exposure out of range";
    for (std::size_t i = 0; i < sc.objects.size(); ++i) {
        const Object& o = sc.objects[i];
        if (!finite(o.direct()) || !finite(glm::dmat4(affine_inverse(o.md))))
            return "object transform not finite: " + sc.where(i).str();
        if (shape_param(o.kind).present() && (!(o.param > 0) || !std::isfinite(o.param)))
            return std::string(shape_kind_name(o.kind)) + " " + std::string(shape_param(o.kind).key) +
                   " invalid: " + sc.where(i).str();
        if (o.material >= sc.materials.size()) return "material index out of range: " + sc.where(i).str();
        const Material& m = sc.material_of(o);
        if (!finite(glm::dvec3(o.color)) || !(m.ior > 0) || !(m.cell > 0) || !std::isfinite(m.cell))
            return "material invalid: " + sc.where(i).str();
    }
    for (const Light& l : sc.lights) {
        if (!finite(l.pos) || !finite(l.color)) return "light not finite";
        if (std::fabs(glm::length(l.dir) - 1.0) > 1e-9) return "light direction not unit length";
    }
    const glm::dmat4 cam = sc.camera.world_from_canonical(s.width, s.height);
    if (!finite(cam) || !finite(glm::inverse(cam))) return "camera transform not finite or not invertible";
    if (!(sc.camera.aperture >= 0) || !(sc.camera.aperture <= 3.5e38) ||
        !(sc.camera.focus_distance(cam) > 0) || !std::isfinite(sc.camera.focus_distance(cam)))
        return "camera lens (aperture, focus) out of range";
    for (int stream = 0; stream < 2; ++stream) {
        const MemoryEstimate est = estimate_render_memory(sc, stream == 1, 2);
        if (!(est.total_bytes >= est.framebuffer_bytes) || !(est.framebuffer_bytes > 0)) return "memory estimate";
        try {
            check_render_memory(sc, stream == 1, 2);
        } catch (const MemoryShortage& e) {
            if (std::string(e.what()).find('\n') != std::string::npos) return "multi-line memory error";
        }
    }
    return "";
}

}  // namespace streamrt_fuzz
