// The scene reader's settings, camera, light and material statements (docs/scene-format.md).
#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "scene/animation.h"
#include "scene/parser_state.h"

namespace streamrt::scene_reader {

const Token& Parser::single_value(const Statement& st, const std::vector<Token>& toks,
                                 std::string_view what) {
    if (toks.size() < 2)
        st.fail_here("expected " + std::string(what) + " after '" + std::string(st.word()) + "'");
    if (toks.size() > 2)
        st.fail(toks[2].column, "unexpected " + quote(toks[2].text) + " after the value of '" +
                                    std::string(st.word()) + "'");
    return toks[1];
}

void Parser::image(Statement& st, const std::vector<Token>& toks) {
    st.read_args(toks, 1, kImageKeys);
    RenderSettings& s = scene.settings;
    for (const Arg& a : st.args) {
        const auto k = a.key;
        if (k == "width") s.width = st.integer(a, 1, 32768);
        else if (k == "height") s.height = st.integer(a, 1, 32768);
        else if (k == "spp") s.spp = st.integer(a, 1, 65536);
        else if (k == "depth") s.depth = st.integer(a, 0, 256);
        else if (k == "degree") s.degree = st.integer(a, 0, 6);
        else if (k == "cutoff") s.cutoff = st.in_closed(a, 0.0, 1.0);
        else if (k == "adaptive") s.adaptive = st.in_closed(a, 0.0, 1.0);
        else if (k == "output") {
            s.output = std::string(a.value);
            scene.output_at = SourceLoc{st.file(), st.line(), a.value_col};
        }
        else if (k == "frames") frame_range(st, a, s.frames_first, s.frames_last);
        else if (k == "sampler") s.pattern = st.word(a, kSamplePatternNames);
        else if (k == "calibration") s.calibration = st.word(a, kCalibrationNames);
        else display_key(st, a, s);
    }
}

void Parser::display_key(const Statement& st, const Arg& a, RenderSettings& s) {
    const auto k = a.key;
    if (k == "exposure") {
        // Bounded so that it stays a normal float factor for the 8-bit conversion.
        const double v = st.number(a);
        if (!(v >= 1e-6 && v <= 1e6))
            st.fail(a.value_col, "'exposure' must be a multiplier > 0, in [1e-6, 1e6], got " + quote(a.value));
        s.exposure = v;
    } else if (k == "colorspace") {
        s.colorspace = st.word(a, kColorSpaceNames);
    } else if (k == "tonemap") {
        s.tonemap = st.word(a, kTonemapNames);
    } else if (k == "exr") {
        s.exr = st.word(a, kExrPixelsNames);
    }
}

void Parser::ambient(Statement& st, const std::vector<Token>& toks) {
    const Token& t = single_value(st, toks, "a number in [0, 1]");
    const Arg a{"ambient", t.column, t.text, t.column};
    scene.settings.ambient = st.in_closed(a, 0.0, 1.0);
}

void Parser::background(Statement& st, const std::vector<Token>& toks) {
    const Token& t = single_value(st, toks, "a colour r,g,b");
    const Arg a{"background", t.column, t.text, t.column};
    scene.settings.background = st.color(a);
}

void Parser::camera(Statement& st, const std::vector<Token>& toks) {
    st.read_args(toks, 1, kCameraKeys);
    Camera cam;
    // The lens keys and name= belong to both forms; the first other key chooses the form.
    const auto either_form = [](const Arg& a) { return same(a.key, "name") || contains(kLensKeys, a.key); };
    if (const auto placing = std::find_if_not(st.args.begin(), st.args.end(), either_form);
        placing != st.args.end()) {
        const Arg& first = *placing;
        const bool look_at = contains(kLookAtKeys, first.key);
        for (const Arg& a : st.args)
            if (!either_form(a) && contains(kLookAtKeys, a.key) != look_at)
                st.fail(a.key_col, "camera: " + quote(a.key) + " belongs to the " +
                                       (look_at ? "explicit" : "look-at") + " form but " +
                                       quote(first.key) + " chose the " +
                                       (look_at ? "look-at" : "explicit") +
                                       " form; use one form per camera statement");
        cam.look_at = look_at;
    }
    for (const Arg& a : st.args) {  // depth of field (the stream engine's lens is float)
        if (a.key != "aperture" && a.key != "focus") continue;
        const double v = a.key == "aperture" ? st.at_least_zero(a) : st.positive(a);
        if (!(v <= double(std::numeric_limits<float>::max())))
            st.fail(a.value_col, quote(a.key) + " must be at most 3.4e38 (single precision), got " + quote(a.value));
        (a.key == "aperture" ? cam.aperture : cam.focus) = v;
    }
    if (cam.look_at) {
        const Arg* up = nullptr;
        for (const Arg& a : st.args) {
            if (a.key == "eye") cam.eye = st.vec3(a);
            else if (a.key == "look") cam.look = st.vec3(a);
            else if (a.key == "up") {
                cam.up = st.direction(a);
                up = &a;
            } else if (a.key == "fov") cam.fov = st.in_open(a, 0.0, 180.0);
        }
        const glm::dvec3 fwd = cam.look - cam.eye;
        if (!(glm::length(fwd) > 0.0) || !std::isfinite(glm::length(fwd)))
            st.fail_here("camera: 'eye' and 'look' must be distinct points");
        const double side = glm::length(glm::cross(glm::normalize(fwd), cam.up));
        if (!(side > 1e-9)) {
            const std::string msg = "camera: 'up' must not be parallel to the view direction";
            if (up) st.fail(up->value_col, msg);
            st.fail_here(msg);
        }
        // The conversion happens once the image size is known; check it is invertible.
        if (singular(cam.world_from_canonical(1, 1)))
            st.fail_here("camera: the look-at placement gives a singular transform");
    } else {
        double rx = 1.0, ry = 1.0, df = 1.0;
        glm::dmat4 xf(1.0);
        for (const Arg& a : st.args) {
            if (a.key == "rx") rx = st.positive(a);
            else if (a.key == "ry") ry = st.positive(a);
            else if (a.key == "df") df = st.positive(a);
            else apply_transform_key(st, a, xf);
        }
        cam.md = xf * scale_matrix({rx, ry, df});
        if (singular(cam.md)) st.fail_here("camera: the composed transform is singular");
    }
    scene.camera = cam;
    if (const Arg* n = st.find("name")) name_thing(st.file(), st.line(), *n, Named::Camera, 0);
}

void Parser::light(Statement& st, const std::vector<Token>& toks) {
    if (toks.size() < 2) st.fail_here("expected a light kind (" + light_kind_names() + ") after 'light'");
    const Token& kt = toks[1];
    const std::optional<LightKind> kind = light_kind_named(kt.text);
    if (!kind) st.fail(kt.column, "expected a light kind (" + light_kind_names() + "), got " + quote(kt.text));
    Light l;
    l.kind = *kind;
    // The kind's keys, required keys and checks come from its definition (lights/lights.h).
    visit_light(l.kind, [&](auto def) {
        using Def = decltype(def);
        st.read_args(toks, 2, std::vector<std::string_view>(std::begin(Def::keys), std::end(Def::keys)));
        for (const Arg& a : st.args) light_key(st, a, l);
        for (std::string_view key : Def::required)
            if (!st.find(key))
                st.fail_here("light " + std::string(Def::name) + " needs '" + std::string(key) + "=" +
                             std::string(key == "radius" ? "r" : "x,y,z") + "'");
        const LightProblem problem = Def::check(l);
        if (!problem.key.empty()) {
            const Arg* at = st.find(problem.key);
            const std::string msg = problem.message + (problem.with_value && at ? ", got " + quote(at->value) : "");
            if (at) st.fail(at->value_col, msg);
            st.fail_here(msg);
        }
        return 0;
    });
    scene.lights.push_back(l);
    if (const Arg* n = st.find("name"))
        name_thing(st.file(), st.line(), *n, Named::Light, std::uint32_t(scene.lights.size() - 1));
}

void Parser::light_key(const Statement& st, const Arg& a, Light& l) {
    if (a.key == "pos") l.pos = st.vec3(a);
    else if (a.key == "dir") l.dir = st.direction(a);
    else if (a.key == "angle") l.angle = st.in_open(a, 0.0, 180.0);
    else if (a.key == "color") l.color = st.color(a);
    else if (a.key == "radius") l.radius = st.positive(a);
    else if (a.key == "u") l.u = st.vec3(a);
    else if (a.key == "v") l.v = st.vec3(a);
    else if (a.key == "samples") l.samples = st.integer(a, 1, 4096);
    else if (a.key == "soft") l.soft = st.at_least_zero(a);
    else if (a.key == "falloff") l.falloff = st.word(a, kFalloffNames);
}

const Appearance& Parser::lookup_material(const Statement& st, const Arg& a) const {
    const auto it = materials_.find(a.value);
    if (it == materials_.end() || it->second.from_line > st.line())
        st.fail(a.value_col, "unknown material " + quote(a.value) +
                                 " (a material must be defined before it is used)");
    return it->second.look;
}

void Parser::material(Statement& st, const std::vector<Token>& toks) {
    if (toks.size() < 2 || toks[1].text.find('=') != std::string_view::npos)
        st.fail(toks.size() < 2 ? toks[0].column : toks[1].column,
                "expected a material name after 'material'");
    const Token& name = toks[1];
    if (const auto it = materials_.find(name.text); it != materials_.end())
        st.fail(name.column, "material " + quote(name.text) + " is already defined");
    st.read_args(toks, 2, kMaterialStatementKeys);  // "material": a base to start from
    Appearance m;
    if (const Arg* base = st.find("material")) m = lookup_material(st, *base);
    for (const Arg& a : st.args) material_key(st, a, m);
    materials_.emplace(std::string(name.text), MaterialDef{m, chunked_ ? st.line() : 0});
}

void Parser::frame_range(const Statement& st, const Arg& a, int& first, int& last) {
    std::string why;
    if (!parse_frame_range(a.value, first, last, why)) st.fail(a.value_col, "'frames': " + why);
}

}  // namespace streamrt::scene_reader
