// The scene reader's names and key statements (docs/scene-format.md, "Animation").
#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "scene/parser_state.h"

#include "scene/animation.h"

namespace streamrt::scene_reader {

const char* Parser::named_word(Named w) {
    return w == Named::Object ? "object" : w == Named::Light ? "light" : w == Named::Csg ? "csg object" : "camera";
}

void Parser::name_thing(const std::string& file, int line, const Arg& a, Named what, std::uint32_t index) {
    if (defer_names_) {
        deferred_names_.push_back({file, line, a, what, index});
        return;
    }
    const auto fail = [&](std::string_view msg) { throw SceneError(SourceLoc{file, line, a.value_col}, msg); };
    const std::string_view n = a.value;
    const auto word_char = [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
               c == '-' || c == '.';
    };
    if (!(std::isalpha(static_cast<unsigned char>(n[0])) || n[0] == '_') ||
        !std::all_of(n.begin(), n.end(), word_char) || n.size() > 64)
        fail("a name starts with a letter or '_' and holds letters, digits, '_', '-' or '.' (at most 64), got " +
             quote(n));
    if (const auto it = names_.find(n); it != names_.end())
        fail("name " + quote(n) + " is already given to the " + named_word(it->second.what) + " of line " +
             std::to_string(it->second.line));
    names_.emplace(std::string(n), NameDef{what, index, line});
}

Animation& Parser::animation() {
    if (!animation_) animation_ = std::make_shared<Animation>();
    return *animation_;
}

void Parser::key(Statement& st, const std::vector<Token>& toks) {
    if (toks.size() < 2 || toks[1].text.find('=') != std::string_view::npos)
        st.fail(toks.size() < 2 ? toks[0].column : toks[1].column,
                "expected a name after 'key' (given with name= on an object, a light or the camera)");
    const Token& nt = toks[1];
    const auto it = names_.find(nt.text);
    if (it == names_.end())
        st.fail(nt.column, "key for an unknown name " + quote(nt.text) +
                               " (name= on an object, light or camera before this line)");
    const NameDef& def = it->second;
    st.read_args(toks, 2, kKeyKeys);
    const std::vector<std::string_view>& fits = def.what == Named::Object || def.what == Named::Csg ? kObjectKeyKeys
                                                : def.what == Named::Light ? kLightKeyKeys
                                                                           : kCameraKeyKeys;
    const std::string who = std::string(named_word(def.what)) + " " + quote(nt.text);
    for (const Arg& a : st.args)
        if (!contains(fits, a.key)) {
            std::string msg = "key: " + quote(a.key) + " does not fit the " + who + " (expected one of:";
            for (auto k : fits) (msg += ' ') += k;
            st.fail(a.key_col, msg + ")");
        }
    const Arg* fa = st.find("frame");
    if (!fa) st.fail_here("key needs 'frame=F' (an integer >= 0)");
    const int frame = st.integer(*fa, 0, kMaxFrame);
    if (st.args.size() < 2) st.fail_here("key: nothing keyed at frame " + std::to_string(frame) + " for " + who);
    const auto [seen, added] = key_lines_.try_emplace({std::string(nt.text), frame}, st.line());
    if (!added)
        st.fail(fa->value_col, who + " already has a key at frame " + std::to_string(frame) + " (line " +
                                   std::to_string(seen->second) + ")");
    Animation& anim = animation();
    if (def.what == Named::Object || def.what == Named::Csg) {
        ObjectTrack* keyed;
        if (def.what == Named::Object) {
            const auto [t, fresh] = object_tracks_.try_emplace(def.index, anim.objects.size());
            if (fresh) {
                anim.objects.emplace_back();
                anim.objects.back().object = def.index;
                anim.objects.back().base = scene.objects[def.index].md;
            }
            keyed = &anim.objects[t->second];
        } else {
            // The block has ended (a key cannot be inside one): its shapes are all read.
            const auto [t, fresh] = csg_tracks_.try_emplace(def.index, anim.csg.size());
            if (fresh) {
                const CsgObject& o = scene.csg_objects[def.index];
                anim.csg.emplace_back();
                anim.csg.back().csg = def.index;
                for (std::uint32_t i = 0; i < o.shape_count; ++i)
                    anim.csg.back().base.push_back(scene.csg_shapes[o.first_shape + i].md);
            }
            keyed = &anim.csg[t->second].keys;
        }
        ObjectTrack& tr = *keyed;
        for (const Arg& a : st.args) {
            if (same(a.key, "translate")) tr.translate.add(frame, st.vec3(a));
            else if (same(a.key, "scale")) {
                const glm::dvec3 sc = st.scale(a);
                if (!(sc.x > 0 && sc.y > 0 && sc.z > 0))
                    st.fail(a.value_col, "a keyed scale must be > 0 in every component, got " + quote(a.value));
                tr.scale.add(frame, sc);
            } else if (same(a.key, "rotate")) tr.rotate.add(frame, rotation(st, a));
        }
        // Md at every key of the object stays usable (interpolation stays between them).
        for (const auto* track : {&tr.translate.frames, &tr.scale.frames, &tr.rotate.frames})
            for (const int f : *track)
                if (singular(keyed_transform(tr, f) * glm::dmat4(tr.base)))
                    st.fail_here("key: the " + who + "'s transform at frame " + std::to_string(f) +
                                 " is singular or not finite");
    } else if (def.what == Named::Light) {
        const auto [t, fresh] = light_tracks_.try_emplace(def.index, anim.lights.size());
        if (fresh) {
            anim.lights.emplace_back();
            anim.lights.back().light = def.index;
        }
        LightTrack& tr = anim.lights[t->second];
        for (const Arg& a : st.args) {
            if (same(a.key, "pos")) {
                if (scene.lights[def.index].kind == LightKind::Directional)
                    st.fail(a.key_col, "key: the " + who + " is directional: it has no 'pos'");
                tr.pos.add(frame, st.vec3(a));
            } else if (same(a.key, "color")) tr.color.add(frame, st.color(a));
        }
    } else {
        if (!scene.camera.look_at)
            st.fail(nt.column, "key: the " + who + " has the explicit form; keys need the look-at form (eye=, look=)");
        CameraTrack& tr = anim.camera;
        for (const Arg& a : st.args) {
            if (same(a.key, "eye")) tr.eye.add(frame, st.vec3(a));
            else if (same(a.key, "look")) tr.look.add(frame, st.vec3(a));
            else if (same(a.key, "fov")) tr.fov.add(frame, st.in_open(a, 0.0, 180.0));
        }
        // The camera at this key's frame passes the camera statement's checks.
        Camera c = scene.camera;
        if (!tr.eye.empty()) c.eye = sample(tr.eye, frame);
        if (!tr.look.empty()) c.look = sample(tr.look, frame);
        if (!tr.fov.empty()) c.fov = sample(tr.fov, frame);
        const glm::dvec3 fwd = c.look - c.eye;
        if (!(glm::length(fwd) > 0.0) || !std::isfinite(glm::length(fwd)) ||
            !(glm::length(glm::cross(glm::normalize(fwd), c.up)) > 1e-9) ||
            singular(c.world_from_canonical(1, 1)))
            st.fail_here("key: at frame " + std::to_string(frame) +
                         " the camera's eye and look coincide, or the view is parallel to 'up'");
        camera_key_ = st.where();
    }
}

glm::dquat Parser::rotation(const Statement& st, const Arg& a) {
    const auto comma = a.value.rfind(',');
    const auto axis = comma == std::string_view::npos ? std::nullopt : to_vec3(a.value.substr(0, comma));
    const auto deg = comma == std::string_view::npos ? std::nullopt : to_number(a.value.substr(comma + 1));
    if (!axis || !deg)
        st.fail(a.value_col, "expected an axis and an angle ax,ay,az,degrees for 'rotate', got " + quote(a.value));
    const double len = glm::length(*axis);
    if (!(len > 0.0) || !std::isfinite(len))
        st.fail(a.value_col, "the axis of 'rotate' must be a non-zero vector, got " + quote(a.value));
    return glm::angleAxis(*deg * (3.14159265358979323846 / 180.0), *axis / len);
}

void Parser::finish() {
    scene.check_object_count();
    if (!animation_) return;
    scene.animation = std::move(animation_);
    try {
        set_frame(scene, 0);
    } catch (const UsageError& e) {
        throw SceneError(camera_key_, e.what());
    }
}

}  // namespace streamrt::scene_reader
