#pragma once
// Animation (docs/scene-format.md, "Animation"): objects, lights and the look-at camera named
// with `name=` and keyed at integer frames by `key NAME frame=F ...` statements. Each keyed
// quantity is its own track (a key statement adds one key to each track it mentions), sampled
// at a frame by linear interpolation between the two keys around it (rotations: quaternion
// slerp along the shortest arc), holding the first / last key outside the keyed range.
//
// A scene without key statements has no Animation at all (Scene::animation is null): no
// memory, and no per-frame work anywhere.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace streamrt {

struct Scene;

/// One quantity's keys, frames strictly increasing.
template <class T>
struct Track {
    std::vector<int> frames;
    std::vector<T> values;

    bool empty() const { return frames.empty(); }
    /// Adds a key, kept in frame order (the parser refuses two keys at one frame).
    void add(int frame, const T& value);
    /// The two keys around `frame` and the weight of the second: first = second with weight 0
    /// outside the keyed range or on a key.
    void bracket(int frame, std::size_t& a, std::size_t& b, double& t) const;
};

/// An object's keys. Its Md at a frame is T(translate) R(rotate) S(scale) Md_statement: the
/// statement's own transform places the shape, the keys move the placed shape (a track
/// without keys is the identity).
struct ObjectTrack {
    std::uint32_t object = 0;  ///< index in Scene::objects
    glm::dmat4x3 base{1.0};    ///< the statement's Md
    Track<glm::dvec3> translate, scale;
    Track<glm::dquat> rotate;
};

/// A CSG object's keys (a `csg` block's name=): T R S applied after the block's own transform,
/// to every shape of the object alike.
struct CsgTrack {
    std::uint32_t csg = 0;                 ///< index in Scene::csg_objects
    std::vector<glm::dmat4x3> base;        ///< its shapes' Md as read, in order from first_shape
    ObjectTrack keys;                      ///< the keyed T R S (its object and base unused)
};

/// A light's keys: they replace its position and colour.
struct LightTrack {
    std::uint32_t light = 0;  ///< index in Scene::lights
    Track<glm::dvec3> pos, color;
};

/// The look-at camera's keys: they replace eye, look and fov.
struct CameraTrack {
    Track<glm::dvec3> eye, look;
    Track<double> fov;
    bool empty() const { return eye.empty() && look.empty() && fov.empty(); }
};

struct Animation {
    std::vector<ObjectTrack> objects;
    std::vector<CsgTrack> csg;
    std::vector<LightTrack> lights;
    CameraTrack camera;
};

/// What a frame changed relative to the scene's previous state: the engines' per-frame
/// update (driver/render.h) rebuilds only these.
struct FrameChange {
    std::vector<std::uint32_t> objects;  ///< scene indices of the objects whose Md changed
    std::vector<std::uint32_t> csg;      ///< indices of the CSG objects that moved (Scene::csg_objects)
    bool lights = false;
    bool camera = false;
    bool any() const { return !objects.empty() || !csg.empty() || lights || camera; }
};

/// The largest frame number.
inline constexpr int kMaxFrame = 1000000;

/// "A..B" (or "A": one frame), integers 0 <= A <= B <= kMaxFrame, for `image frames=` and
/// `--frames`; false with the reason in `why` otherwise.
bool parse_frame_range(std::string_view text, int& first, int& last, std::string& why);

/// Linear interpolation of a vector track at `frame` (the track must have keys).
glm::dvec3 sample(const Track<glm::dvec3>& track, int frame);
double sample(const Track<double>& track, int frame);
/// Slerp along the shortest arc, normalised.
glm::dquat sample(const Track<glm::dquat>& track, int frame);

/// The keyed part T R S of an object's Md at `frame` (identity for tracks without keys).
glm::dmat4 keyed_transform(const ObjectTrack& track, int frame);

/// Puts a scene being built at `frame`: keyed objects' Md, keyed lights, the keyed camera.
/// Returns what differs from the scene's state before the call. A scene without animation:
/// nothing. Throws UsageError when the camera is degenerate at that frame (eye on look).
/// The reader puts its scene at frame 0 with it, scene_at_frame its new scene at the frame
/// asked for; a scene the reader has returned is never put at another frame.
FrameChange set_frame(Scene& scene, int frame);

/// The scene at `frame` (< 0: the scene as read) as a new scene built from `base`, the scene
/// as read (frame 0), which is left as it is: `base` itself when that frame changes nothing
/// (no animation, frame 0, keys that hold frame 0's values). UsageError as set_frame.
std::shared_ptr<const Scene> scene_at_frame(const std::shared_ptr<const Scene>& base, int frame);

/// What differs between frames `from` and `to` of one animation (frames < 0: frame 0), as
/// set_frame would report putting a scene at `from` at `to`: what an engine set up at `from`
/// re-derives (PreparedRender::update).
FrameChange frame_change(const Animation& animation, int from, int to);

}  // namespace streamrt
