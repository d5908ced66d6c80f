#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace streamrt {

namespace {
/// A frame number: decimal digits only, at most kMaxFrame.
bool frame_number(std::string_view s, int& out, std::string& why, const char* which) {
    const std::string shown = quote(s);  // what was typed may hold control bytes
    if (s.empty() || s.size() > 9 || !std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        why = std::string("the ") + which + " frame must be an integer >= 0, got " + shown;
        return false;
    }
    out = std::stoi(std::string(s));
    if (out > kMaxFrame) {
        why = std::string("the ") + which + " frame must be at most " + std::to_string(kMaxFrame) + ", got " + shown;
        return false;
    }
    return true;
}
}  // namespace

bool parse_frame_range(std::string_view text, int& first, int& last, std::string& why) {
    const auto dots = text.find("..");
    const std::string_view a = text.substr(0, dots);
    const std::string_view b = dots == std::string_view::npos ? a : text.substr(dots + 2);
    if (!frame_number(a, first, why, "first") || !frame_number(b, last, why, "last")) {
        why += " (expected A..B, e.g. 0..23)";
        return false;
    }
    if (last < first) {
        why = "the range " + std::string(text) + " runs backwards (the last frame comes before the first)";
        return false;
    }
    return true;
}

template <class T>
void Track<T>::add(int frame, const T& value) {
    const auto at = std::lower_bound(frames.begin(), frames.end(), frame);
    const auto i = at - frames.begin();
    frames.insert(at, frame);
    values.insert(values.begin() + i, value);
}

template <class T>
void Track<T>::bracket(int frame, std::size_t& a, std::size_t& b, double& t) const {
    t = 0.0;
    if (frame <= frames.front()) {
        a = b = 0;
        return;
    }
    if (frame >= frames.back()) {
        a = b = frames.size() - 1;
        return;
    }
    b = std::size_t(std::upper_bound(frames.begin(), frames.end(), frame) - frames.begin());
    a = b - 1;
    t = double(frame - frames[a]) / double(frames[b] - frames[a]);
}

template struct Track<glm::dvec3>;
template struct Track<double>;
template struct Track<glm::dquat>;

glm::dvec3 sample(const Track<glm::dvec3>& track, int frame) {
    std::size_t a, b;
    double t;
    track.bracket(frame, a, b, t);
    return t == 0.0 ? track.values[a] : (1.0 - t) * track.values[a] + t * track.values[b];
}

double sample(const Track<double>& track, int frame) {
    std::size_t a, b;
    double t;
    track.bracket(frame, a, b, t);
    return t == 0.0 ? track.values[a] : (1.0 - t) * track.values[a] + t * track.values[b];
}

glm::dquat sample(const Track<glm::dquat>& track, int frame) {
    std::size_t a, b;
    double t;
    track.bracket(frame, a, b, t);
    if (t == 0.0) return track.values[a];
    // glm::slerp negates the second quaternion when their dot product is negative: q and -q
    // are the same rotation, and the negated one is the end of the shorter arc.
    return glm::normalize(glm::slerp(track.values[a], track.values[b], t));
}

glm::dmat4 keyed_transform(const ObjectTrack& track, int frame) {
    glm::dmat4 m(1.0);
    if (!track.scale.empty()) {
        const glm::dvec3 s = sample(track.scale, frame);
        m[0][0] = s.x, m[1][1] = s.y, m[2][2] = s.z;
    }
    if (!track.rotate.empty()) m = glm::dmat4(glm::mat3_cast(sample(track.rotate, frame))) * m;
    if (!track.translate.empty()) m[3] = glm::dvec4(sample(track.translate, frame), 1.0);
    return m;
}

namespace {
/// An object's Md at `frame`: its keys' T R S times its statement's Md.
glm::dmat4x3 keyed_md(const ObjectTrack& t, int frame) {
    return glm::dmat4x3(keyed_transform(t, frame) * glm::dmat4(t.base));
}
}  // namespace

FrameChange set_frame(Scene& scene, int frame) {
    FrameChange change;
    if (!scene.animation) return change;
    const Animation& anim = *scene.animation;
    for (const ObjectTrack& t : anim.objects) {
        Object& o = scene.objects[t.object];
        const glm::dmat4x3 md = keyed_md(t, frame);
        if (md != o.md) {
            o.md = md;
            change.objects.push_back(t.object);
        }
    }
    for (const CsgTrack& t : anim.csg) {
        const glm::dmat4 keyed = keyed_transform(t.keys, frame);
        const std::uint32_t first = scene.csg_objects[t.csg].first_shape;
        bool moved = false;
        for (std::size_t i = 0; i < t.base.size(); ++i) {
            const glm::dmat4x3 md(keyed * glm::dmat4(t.base[i]));
            Object& o = scene.csg_shapes[first + i];
            moved = moved || md != o.md;
            o.md = md;
        }
        if (moved) change.csg.push_back(t.csg);
    }
    for (const LightTrack& t : anim.lights) {
        Light& l = scene.lights[t.light];
        const Light before = l;
        if (!t.pos.empty()) l.pos = sample(t.pos, frame);
        if (!t.color.empty()) l.color = sample(t.color, frame);
        change.lights = change.lights || l.pos != before.pos || l.color != before.color;
    }
    const CameraTrack& ct = anim.camera;
    if (!ct.empty()) {
        Camera& c = scene.camera;
        const Camera before = c;
        if (!ct.eye.empty()) c.eye = sample(ct.eye, frame);
        if (!ct.look.empty()) c.look = sample(ct.look, frame);
        if (!ct.fov.empty()) c.fov = sample(ct.fov, frame);
        const glm::dvec3 fwd = c.look - c.eye;
        if (!(glm::length(fwd) > 0.0) || !(glm::length(glm::cross(glm::normalize(fwd), c.up)) > 1e-9))
            throw UsageError("frame " + std::to_string(frame) +
                             ": the keyed camera's view direction is zero or parallel to 'up'");
        change.camera = c.eye != before.eye || c.look != before.look || c.fov != before.fov;
    }
    return change;
}

FrameChange frame_change(const Animation& anim, int from, int to) {
    from = std::max(from, 0), to = std::max(to, 0);
    FrameChange change;
    if (from == to) return change;
    for (const ObjectTrack& t : anim.objects)
        if (keyed_md(t, from) != keyed_md(t, to)) change.objects.push_back(t.object);
    for (const CsgTrack& t : anim.csg)
        if (keyed_transform(t.keys, from) != keyed_transform(t.keys, to)) change.csg.push_back(t.csg);
    const auto moved = [&](const auto& track) { return !track.empty() && sample(track, from) != sample(track, to); };
    for (const LightTrack& t : anim.lights) change.lights = change.lights || moved(t.pos) || moved(t.color);
    change.camera = moved(anim.camera.eye) || moved(anim.camera.look) || moved(anim.camera.fov);
    return change;
}

std::shared_ptr<const Scene> scene_at_frame(const std::shared_ptr<const Scene>& base, int frame) {
    // The scene as read is at frame 0: a frame with frame 0's values is that scene.
    if (!base->animation || !frame_change(*base->animation, 0, frame).any()) return base;
    auto at = std::make_shared<Scene>(*base);  // a new scene: the objects are copied once
    set_frame(*at, frame);
    return at;
}

}  // namespace streamrt
