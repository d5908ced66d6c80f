#pragma once
// The scene reader's state and its statements (docs/architecture.md, "Scene reading"):
// the one-pass and chunked reading (scene/parser.cpp), the settings, camera, light and
// material statements (parse_statements.cpp), shapes, meshes, textures and includes
// (parse_shapes.cpp), names and keys (parse_animation.cpp). Internal to the reader.
#include <climits>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "core/memory_budget.h"
#include "mesh/mesh.h"
#include "scene/file_text.h"
#include "scene/parser.h"
#include "scene/scene.h"
#include "scene/scene_keys.h"
#include "scene/statement.h"

namespace streamrt::scene_reader {

/// Per-thread lexing scratch: the token and argument lists of the line being read.
struct Scratch {
    std::vector<Token> toks;
    std::vector<Arg> args;
};

/// A material and the first line it may be used from (0 when read in one pass: whatever is
/// defined is usable, as statements run in order).
struct MaterialDef {
    Appearance look;
    int from_line = 0;
};

/// Where a pass puts the materials of the objects it reads: the scene's own deduplicated list
/// (one pass), or a chunk's private list, merged into the scene's in chunk order afterwards
/// (so the scene's list is the same for every thread count).
class MaterialList {
  public:
    std::uint32_t intern(const Material& m) {
        if (scene_) return scene_->intern_material(m);
        const auto [it, added] = index_.try_emplace(m, std::uint32_t(list_.size()));
        if (added) list_.push_back(m);
        return it->second;
    }
    explicit MaterialList(Scene* scene = nullptr) : scene_(scene) {}
    const std::vector<Material>& local() const { return list_; }

  private:
    Scene* scene_;
    std::unordered_map<Material, std::uint32_t, MaterialHash> index_;
    std::vector<Material> list_;
};

/// One chunk of a large text: complete lines [begin, end).
struct Chunk {
    std::size_t begin = 0, end = 0;
    int first_line = 0;                  // line number of `begin`
    std::size_t first_object = 0;        // its first slot in scene.objects
    MaterialList materials;              // its objects' materials, indexed by them until merged
    std::size_t shapes = 0;              // shape statements in it
    int lines = 0;                       // '\n' in it
    std::vector<std::pair<std::size_t, int>> others;  // non-shape statements: offset, line in chunk
    bool sequential_only = false;        // holds include or mesh
    std::exception_ptr error;            // the first one in the chunk
    int error_line = INT_MAX;
    struct Name {
        std::string_view text;
        int line, column;
        std::size_t slot;
    };
    std::vector<Name> names;             // the name= of its shapes (animation), in order
};

class Parser {
  public:
    Scene scene;

    explicit Parser(const ReadOptions& options) : options_(options) {}

    /// Reads a top-level text: chunked and in parallel when it is large and plain, else in
    /// one pass. `mapped`: the text is a private file mapping whose pages may be released.
    void read_top(std::string_view text, const std::string& display, const fs::path& id, bool mapped) {
        if (text.size() >= options_.chunked_from && read_chunked(text, display, mapped)) return;
        read_text(text, display, id, 0);
    }

    /// Reads the text of one file. `display` names it in messages; `id` identifies it for
    /// cycle detection; includes are resolved against `display`'s directory.
    void read_text(std::string_view text, const std::string& display, const fs::path& id,
                   int depth) {
        ++files_;
        open_.push_back(id);
        const std::size_t outer_csg_base = file_csg_base_;
        file_csg_base_ = csg_blocks_.size();
        if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 BOM
        int line_no = 0;
        std::size_t pos = 0;
        while (pos <= text.size()) {
            auto nl = text.find('\n', pos);
            if (nl == std::string_view::npos) nl = text.size();
            ++line_no;
            statement(text.substr(pos, nl - pos), display, line_no, depth, scratch_);
            pos = nl + 1;
        }
        check_csg_closed();
        file_csg_base_ = outer_csg_base;
        open_.pop_back();
    }

  private:
    ReadOptions options_;
    bool chunked_ = false;  // materials carry the line they are defined at (see MaterialDef)
    Scratch scratch_;       // the sequential pass's
    std::map<std::string, MaterialDef, std::less<>> materials_;
    std::vector<fs::path> open_;  // the include chain being read
    // By file identity and whether its texture coordinates and vertex colours are kept:
    // loaded once, shared (index in scene.meshes).
    std::map<std::tuple<fs::path, bool, bool>, std::uint32_t> meshes_;
    std::map<std::size_t, std::uint32_t> memory_mesh_index_;  // ReadOptions::memory_meshes -> scene.meshes
    MaterialList scene_materials_{&scene};  // the one-pass reader's: straight into the scene
    int files_ = 0;

    /// The chunked reader. First pass (parallel): cut into chunks at line ends, count lines
    /// and shape statements, note the other statements. Then the other statements run in
    /// file order, then the shapes of every chunk are parsed (parallel) into their own slice
    /// of scene.objects, reserved once. The first error in file order wins. False (nothing
    /// done) when the text holds include or mesh: those are read in one sequential pass.
    bool read_chunked(std::string_view text, const std::string& display, bool mapped);

    static std::string_view line_at(std::string_view text, std::size_t offset);

    /// First pass over a chunk: lines, shapes, the offsets of the other statements.
    static void survey(std::string_view text, Chunk& c);

    /// Second pass over a chunk: its shapes into scene.objects[c.first_object...]; stops at
    /// the chunk's first error (kept with its line).
    void read_shapes(std::string_view text, const std::string& display, std::uint32_t file, Chunk& c);

    void statement(std::string_view line, const std::string& file, int line_no, int depth, Scratch& scratch);

    /// The single positional value of `ambient`, `background` and `include`.
    static const Token& single_value(const Statement& st, const std::vector<Token>& toks,
                                     std::string_view what);

    void image(Statement& st, const std::vector<Token>& toks);

    // The display colour keys of `image` (docs/scene-format.md, "Output and display colour").
    static void display_key(const Statement& st, const Arg& a, RenderSettings& s);

    void ambient(Statement& st, const std::vector<Token>& toks);

    void background(Statement& st, const std::vector<Token>& toks);

    void camera(Statement& st, const std::vector<Token>& toks);

    void light(Statement& st, const std::vector<Token>& toks);

    /// One key of a light statement, read into its field (each kind takes some of them).
    static void light_key(const Statement& st, const Arg& a, Light& l);

    /// The material named by `a`, as defined at this statement: the chunked reader has read
    /// every material statement first, so one defined on a later line is refused here.
    const Appearance& lookup_material(const Statement& st, const Arg& a) const;

    void material(Statement& st, const std::vector<Token>& toks);

    /// One material key of a material or shape statement into `look` (scene_keys.h,
    /// apply_material_key), texture files read through texture_file; false for another key.
    bool material_key(const Statement& st, const Arg& a, Appearance& look) {
        return apply_material_key(st, a, look, [&](const Arg& file) { return texture_file(st, file); });
    }

    /// What a shape statement says, before it becomes an Object (make_object).
    struct ShapeFields {
        ShapeKind kind = ShapeKind::Sphere;
        Appearance look;
        glm::dmat4 md{1.0};
        double param = 0.0;  // the shape's parameter (ShapeParam: the torus's minor)
        bool smooth = false;
        std::optional<std::uint32_t> mesh;  // index in scene.meshes
    };

    /// A `csg` block being read (docs/scene-format.md, "CSG"): its node so far, what its
    /// children inherit (its appearance; its transform, applied after theirs) and where its
    /// `csg` word is.
    struct CsgBlock {
        CsgNode node;
        Appearance look;
        glm::dmat4 md{1.0};
        SourceLoc at;
        std::uint32_t file = 0;
        int shapes = 0;  // the outermost block's: all its object's shapes (kMaxCsgShapes)
        std::uint32_t first_shape = 0;  // the outermost block's: its first in scene.csg_shapes
    };
    std::vector<CsgBlock> csg_blocks_;  // innermost last
    std::size_t file_csg_base_ = 0;     // blocks opened before the file being read: not its to end

    /// csg OP keys...: opens a block.
    void csg(Statement& st, const std::vector<Token>& toks);
    /// end: closes the innermost block, checked, into its parent or the scene.
    void csg_end(Statement& st, const std::vector<Token>& toks);
    /// A shape statement inside a block: one of its children.
    void csg_child(Statement& st, const std::vector<Token>& toks, ShapeKind kind);
    /// After a file: a block it opened and did not end is an error at that block's `csg`.
    void check_csg_closed() const;
    /// A mesh child must close a volume (mesh/mesh_solid.h): else an error at its file= value.
    void check_closed_mesh(const Statement& st, std::uint32_t mesh);
    std::unordered_set<std::uint32_t> closed_meshes_;  // scene.meshes already checked

    /// The one place an Object is built from a checked shape statement, in place: `obj` and
    /// `loc` are its slots in scene.objects and scene.object_locs.
    static void make_object(const Statement& st, const ShapeFields& f, std::uint32_t file, MaterialList& materials,
                            Object& obj, ObjectLoc& loc);

    /// A shape statement of the one-pass reader, appended to the scene.
    void one_pass_shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind);

    /// The index of a file name in Scene::files (one-pass reader and set-up only: not
    /// thread-safe).
    std::uint32_t file_index(const std::string& file);
    std::uint32_t last_file_ = 0;

    /// Reads a shape statement into `out` and `loc`; its `name=` argument, if any.
    /// Inside a csg block (`within`), the shape starts from the block's appearance and the
    /// block's transform applies after its own.
    std::optional<Arg> shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind, std::uint32_t file,
                             MaterialList& materials, Object& out, ObjectLoc& loc, const CsgBlock* within = nullptr);

    /// The file `a` names, relative to the statement's file.
    static fs::path target_of(const Statement& st, const Arg& a);

    /// A file read once: its index in `list`, remembered in `known` under key(its identity);
    /// load(path) reads it the first time. Errors at column `col` of the statement.
    template <class Map, class List, class Key, class Load>
    typename Map::mapped_type read_once(const Statement& st, int col, const fs::path& target, const std::string& what,
                                        Map& known, List& list, Key key, Load load) {
        const auto id = key(identity_of(target));
        if (const auto it = known.find(id); it != known.end()) return it->second;
        std::error_code ec;
        if (!fs::is_regular_file(target, ec)) st.fail(col, "cannot open " + what + " file " + quote(target.string()));
        if (options_.copies) copy_file(target);
        record_input(target.string(), what, st, col);
        try {
            auto item = load(target.string());
            const auto index = typename Map::mapped_type(list.size());
            list.push_back(std::move(item));
            known.emplace(id, index);
            return index;
        } catch (const MemoryShortage& e) {
            // Not a mistake in the scene (exit status 1), but said at the same place.
            SourceLoc at = st.where();
            at.column = col;
            throw MemoryShortage(at.str() + ": " + quote(target.string()) + ": " + e.what());
        } catch (const std::exception& e) {
            st.fail(col, quote(target.string()) + ": " + e.what());
        }
    }

    /// The mesh of an OBJ or PLY file, read once per file and per need (texture coordinates
    /// for textured objects, vertex colours for vertex_colors=true ones): its index in
    /// Scene::meshes.
    std::uint32_t mesh_file(const Statement& st, const Arg& a, bool with_uv, bool with_colors);

    /// The texture of an image file, read once per file: its index in Scene::textures.
    /// Shapes of the chunked reader call it from several threads, hence the lock.
    std::int32_t texture_file(const Statement& st, int col, const fs::path& target);
    std::int32_t texture_file(const Statement& st, const Arg& a) { return texture_file(st, a.value_col, target_of(st, a)); }

    /// An OBJ file read with its materials (mesh materials=obj): once per file and need of
    /// texture coordinates; its parts' meshes are in Scene::meshes.
    struct ObjParts {
        std::vector<std::uint32_t> meshes;  ///< per part, index in Scene::meshes
        std::vector<int> materials;         ///< per part, index in `library` (-1: none)
        std::vector<ObjMaterial> library;
        std::string mtl_path;
    };
    const ObjParts& obj_parts(const Statement& st, const Arg& a, bool with_uv);
    std::map<std::pair<fs::path, bool>, std::size_t> obj_models_;
    std::vector<std::pair<Object, ObjectLoc>> extra_objects_;  // a materials=obj statement's parts after the first
    std::vector<ObjParts> obj_parts_;

    /// The material keys an OBJ material sets (docs/scene-format.md, "OBJ materials"), over
    /// the statement's appearance; map_Kd is read relative to the library's folder.
    void apply_obj_material(const Statement& st, const Arg& file, const ObjParts& parts, int material,
                            Appearance& look);
    std::mutex textures_mutex_;
    std::map<fs::path, std::int32_t> textures_;  // by file identity (index in scene.textures)

    void copy_file(const fs::path& p);

    /// Notes a file read, named at column `col` of the statement, in Scene::inputs.
    /// A file read twice (a mesh with and without texture coordinates) is noted once.
    void record_input(const std::string& path, const std::string& what, const Statement& st, int col) {
        for (const SceneInput& in : scene.inputs)
            if (in.path == path) return;
        scene.inputs.push_back(SceneInput{path, what, SourceLoc{st.file(), st.line(), col}});
    }

    void include(Statement& st, const std::vector<Token>& toks, int depth);

    // ---- animation: name= and the key statement (docs/scene-format.md, "Animation") ------
    enum class Named : std::uint8_t { Object, Light, Camera, Csg };
    struct NameDef {
        Named what;
        std::uint32_t index;  // in scene.objects, scene.lights or scene.csg_objects
        int line;
    };
    std::map<std::string, NameDef, std::less<>> names_;  // one namespace for objects, lights, camera
    /// A chunked read records the names of all statements first and checks them in file order.
    struct DeferredName {
        std::string file;
        int line;
        Arg arg;
        Named what;
        std::uint32_t index;
    };
    std::vector<DeferredName> deferred_names_;
    bool defer_names_ = false;
    std::map<std::pair<std::string, int>, int> key_lines_;  // (name, frame) -> line of its key
    std::unordered_map<std::uint32_t, std::size_t> object_tracks_, light_tracks_, csg_tracks_;  // index -> track

    static const char* named_word(Named w);

    /// Records `name=` of a statement at file:line; names are unique across objects, lights
    /// and the camera.
    void name_thing(const std::string& file, int line, const Arg& a, Named what, std::uint32_t index);

    /// The keys read so far (made at the first key statement); given to the scene by finish().
    Animation& animation();
    std::shared_ptr<Animation> animation_;

    /// key NAME frame=F k=v...: one key at frame F for each quantity given.
    void key(Statement& st, const std::vector<Token>& toks);
    SourceLoc camera_key_;  // the last camera key, for an interpolated camera that degenerates

    /// rotate=ax,ay,az,degrees: a rotation about a non-zero axis, as a unit quaternion.
    static glm::dquat rotation(const Statement& st, const Arg& a);

    /// image frames=A..B.
    static void frame_range(const Statement& st, const Arg& a, int& first, int& last);

  public:
    /// After the whole text: the scene gets its keys and is put at frame 0 (a still picture of
    /// an animated scene is frame 0).
    void finish();
};

}  // namespace streamrt::scene_reader
