#pragma once
// The scene model of the handout: lights, shapes (canonical shape + Md/Mn/Mi + material),
// a camera placed by Md, and the render settings. Geometry is in double (Md, lights, camera);
// objects are compact records with an index into deduplicated materials (a scene may hold
// millions). Each engine converts to its own tables when it builds its pipeline.
//
// A scene is immutable once the reader returns it: front ends hold it as
// std::shared_ptr<const Scene> (driver/render_job.h). Overrides live in the render job's
// settings, a frame of an animation is a new scene (scene_at_frame, scene/animation.h).
#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/enum_names.h"
#include "core/error.h"
#include "scene/texture.h"
#include "core/transform.h"
#include "image/display_settings.h"
#include "lights/lights.h"
#include "materials/materials.h"
#include "shapes/shape_kind.h"

namespace streamrt {

struct Mesh;
struct Animation;  // scene/animation.h


/// One object, compact (128 bytes; a scene may hold millions): the canonical shape, Md, the
/// object's colour and the index of its (deduplicated) material. Mi and Mn are not stored:
/// each engine derives what it needs from Md once, in the precision it works in. Where the
/// statement came from is kept apart (Scene::where), since only messages need it.
struct Object {
    /// Md's top three rows (glm: 4 columns of 3); the fourth row of an affine map is 0 0 0 1.
    glm::dmat4x3 md{1.0};
    /// The per-object shape parameter the kernels and shading receive: the torus minor
    /// radius (canonical units), 1 for a smooth mesh, 0 for a flat one, 0 otherwise.
    double param = 0.0;
    /// The handout's Col of the object. Single precision: scene colours carry a few decimals
    /// and end as 8-bit or float pixels.
    glm::vec3 color{1.f, 1.f, 1.f};
    std::uint32_t material = 0;  ///< index into Scene::materials
    std::uint32_t mesh = 0;      ///< Mesh only: index into Scene::meshes
    ShapeKind kind = ShapeKind::Sphere;

    glm::dmat4 direct() const { return glm::dmat4(md); }
};
static_assert(sizeof(Object) == 128, "Object is meant to stay two cache lines");

/// Where an object's statement is, for messages: an index into Scene::files, line, column.
struct ObjectLoc {
    std::uint32_t file = 0;
    std::int32_t line = 0, column = 0;
};

/// Constructive solid geometry (docs/scene-format.md, "CSG"): how a node combines the solids
/// of its children. Merge is a union that keeps only the result's outer surface (for glass).
enum class CsgOp : std::uint8_t { Union, Intersection, Difference, Merge };
inline constexpr EnumName<CsgOp> kCsgOpNames[] = {
    {CsgOp::Union, "union"}, {CsgOp::Intersection, "intersection"}, {CsgOp::Difference, "difference"},
    {CsgOp::Merge, "merge"}};

/// One `csg` block: its operation over its children, in written order (a difference is the
/// first child minus the others). A child is a shape (Scene::csg_shapes) or another node.
struct CsgNode {
    struct Child {
        bool is_node = false;
        std::uint32_t index = 0;  ///< into Scene::csg_nodes or Scene::csg_shapes
    };
    CsgOp op = CsgOp::Union;
    std::vector<Child> children;
};

/// A top-level `csg` block: the object a renderer traces (its root node and the block's
/// statement, for messages).
struct CsgObject {
    std::uint32_t root = 0;  ///< into Scene::csg_nodes
    ObjectLoc loc;
    /// Its shapes: Scene::csg_shapes[first_shape, first_shape + shape_count), in written order.
    std::uint32_t first_shape = 0, shape_count = 0;
};

/// The handout's canonical camera (eye (0,0,1), screen [-1,1]^2 in z=0) placed by Md.
/// Two forms: Md given directly (homothety rx, ry, df then the listed transforms), or
/// look-at (eye, look, up, vertical fov), converted to Md once the image aspect is known.
struct Camera {
    bool look_at = false;
    glm::dmat4 md{1.0};  ///< explicit form
    glm::dvec3 eye{0.0, 0.0, 5.0}, look{0.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
    double fov = 45.0;  ///< look-at form: vertical field of view, degrees
    // Depth of field (both forms): a thin lens of radius `aperture` (world units; 0 = the
    // handout's pinhole) focused on the plane parallel to the screen at distance `focus` along
    // the view axis (0 = the default: |look - eye| in the look-at form, the eye's distance to
    // the screen plane z = 0, |Md (0,0,-1)|, in the explicit form).
    double aperture = 0.0;
    double focus = 0.0;

    /// Md for an image of width x height pixels (the look-at form keeps square pixels).
    glm::dmat4 world_from_canonical(int width, int height) const;
    /// The distance of the plane in focus, `focus` or its default, for this camera's Md.
    double focus_distance(const glm::dmat4& md) const;
};

enum class SamplePattern : std::uint8_t { Stratified, Grid, Random };
inline constexpr EnumName<SamplePattern> kSamplePatternNames[] = {
    {SamplePattern::Stratified, "stratified"}, {SamplePattern::Grid, "grid"}, {SamplePattern::Random, "random"}};

struct RenderSettings {
    int width = 640;
    int height = 480;
    int spp = 1;
    int depth = 5;   ///< maximum number of reflection/refraction bounces after the primary hit
    int degree = 5;  ///< 0 flat .. 5 shadows, cumulative (handout); 6 adds light bounced between surfaces
    double ambient = 0.1;  ///< alpha, the ambient fraction
    /// Weight cut-off: reflected / refracted rays whose throughput (product of the refl and
    /// trans weights from the camera) is below this in every channel are not traced; 0 = all.
    /// The default prunes what an 8-bit picture cannot show: measured (docs/performance.md,
    /// "Weight cut-off"), no pixel of the glass scenes moves by more than one 8-bit step.
    double cutoff = 0.001;
    /// Adaptive sampling (render/adaptive.h): T, the estimated standard error of its mean
    /// luminance at which a pixel of 16 samples stops (one of n samples stops at T (n / 16)^(3/4));
    /// spp is then the most it takes.
    /// 0: every pixel takes spp samples.
    double adaptive = 0.0;
    glm::dvec3 background{0.0, 0.0, 0.0};
    Calibration calibration = Calibration::Clamp;
    SamplePattern pattern = SamplePattern::Stratified;
    std::string output = "out.png";
    // Display colour (docs/scene-format.md, "Output and display colour"): how the linear
    // framebuffer becomes 8-bit PNG/PPM values; PFM and EXR keep the linear values.
    ColorSpace colorspace = ColorSpace::Srgb;
    Tonemap tonemap = Tonemap::Clamp;
    double exposure = 1.0;  ///< > 0, multiplies the linear values before the tone curve
    ExrPixels exr = ExrPixels::Half;
    /// > 0: every area light's samples per shaded point, in place of its own samples= (a
    /// front end's override, --light-samples; no `image` key sets it). 0: each light's own.
    int light_samples = 0;

    // ---- animation (scene/animation.h) ----
    /// `image frames=A..B`: the frames rendered by default (frames_last < frames_first: none
    /// given, one picture of frame 0).
    int frames_first = 0, frames_last = -1;
    bool has_frames() const { return frames_last >= frames_first; }
};

/// The `image` keys' display colour chain (image/display_settings.h).
Display display_of(const RenderSettings& s);

/// The light as a render with these settings samples it: an area light's samples are
/// settings.light_samples when that is set (the scene's own light is not changed).
inline Light rendered_light(Light l, const RenderSettings& s) {
    if (s.light_samples > 0 && l.is_area()) l.samples = s.light_samples;
    return l;
}

/// A file the reader read: the scene file, an included file, a mesh, an OBJ material library
/// or a texture. A render never writes over one (the front ends check every file they would
/// write against these before rendering).
struct SceneInput {
    std::string path;   ///< as read (relative to the working folder, or absolute)
    std::string what;   ///< "the scene file", "included file", "mesh", "material library", "texture"
    SourceLoc named_at; ///< the statement's argument that named it (line 0: the scene file itself)
    /// "texture named at scenes/textured.cfg:14:18", for messages.
    std::string describe() const { return named_at.line > 0 ? what + " named at " + named_at.str() : what; }
};

/// Whether a and b name the same file: the same device and inode when both exist (hard and
/// symbolic links, "./" and ".." spellings all reach the same inode), else the same canonical
/// path (a file that does not exist yet is some other file than one that does).
bool same_file(const std::string& a, const std::string& b);

/// The most objects a scene may hold: the stream engine's kernels carry the closest object's
/// number in float lanes, which are exact up to 2^24.
inline constexpr std::size_t kMaxSceneObjects = std::size_t(1) << 24;

struct Scene {
    std::string path;  ///< the file it was read from
    RenderSettings settings;
    Camera camera;
    std::vector<Light> lights;
    std::vector<Object> objects;
    std::vector<Material> materials;  ///< deduplicated; Object::material indexes it
    std::vector<std::shared_ptr<const Mesh>> meshes;  ///< one per OBJ file; Object::mesh indexes it
    std::vector<std::shared_ptr<const Texture>> textures;  ///< one per image file; Material::texture indexes it
    // CSG (docs/scene-format.md, "CSG"): the objects made of `csg` blocks, their nodes and
    // their shapes (in world space, with their own material; apart from `objects`, which a
    // renderer traces one by one). Empty in a scene without CSG.
    std::vector<CsgObject> csg_objects;
    std::vector<CsgNode> csg_nodes;
    std::vector<Object> csg_shapes;
    /// Cold data, for messages only: the statement of each object (same indexing as objects).
    std::vector<ObjectLoc> object_locs;
    std::vector<std::string> files;  ///< the files objects came from (ObjectLoc::file)
    /// Every file read (each once, in reading order): what no output may overwrite.
    std::vector<SceneInput> inputs;
    /// Where `image output=` was given (line 0: the scene names no output).
    SourceLoc output_at;
    /// The keys of `key` statements (scene/animation.h); null for a scene without keys. The
    /// scene as read is at frame 0; scene_at_frame() builds the scene at another frame as a
    /// new scene (a parsed scene is never changed).
    std::shared_ptr<const Animation> animation;

    const Material& material_of(const Object& o) const { return materials[o.material]; }
    /// The object's mesh (Mesh objects only; nullptr otherwise).
    const Mesh* mesh_of(const Object& o) const {
        return o.kind == ShapeKind::Mesh && o.mesh < meshes.size() ? meshes[o.mesh].get() : nullptr;
    }
    /// The input `path` would write over (same_file), or null.
    const SceneInput* input_at(const std::string& path) const;
    /// The statement that made object i.
    SourceLoc where(std::size_t i) const {
        const ObjectLoc& l = object_locs[i];
        return SourceLoc{files[l.file], l.line, l.column};
    }
    /// The `csg` statement of CSG object i.
    SourceLoc csg_where(std::size_t i) const {
        const ObjectLoc& l = csg_objects[i].loc;
        return SourceLoc{files[l.file], l.line, l.column};
    }
    /// Throws SceneError at the statement of the first object beyond `limit` (kMaxSceneObjects
    /// unless a test asks for less) when the scene holds more.
    void check_object_count(std::size_t limit = kMaxSceneObjects) const;
    /// Adds an object; its material is deduplicated against those already here.
    void add_object(Object o, const Material& m = {}, const ObjectLoc& loc = {});
    /// The index of material m in `materials`, added if no equal one is there.
    std::uint32_t intern_material(const Material& m);

  private:
    std::unordered_map<Material, std::uint32_t, MaterialHash> material_index_;
};

}  // namespace streamrt
