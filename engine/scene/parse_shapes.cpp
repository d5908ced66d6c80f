// The scene reader's shape and mesh statements, the files they read (meshes, textures,
// OBJ material libraries) and include.
#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <vector>

#include "mesh/ply_reader.h"
#include "scene/parser_state.h"

namespace streamrt::scene_reader {

void Parser::make_object(const Statement& st, const ShapeFields& f, std::uint32_t file, MaterialList& materials,
                        Object& obj, ObjectLoc& loc) {
    obj.kind = f.kind;
    obj.md = glm::dmat4x3(f.md);
    obj.param = f.kind == ShapeKind::Mesh ? (f.smooth ? 1.0 : 0.0) : f.param;
    obj.color = glm::vec3(f.look.color);
    obj.material = materials.intern(f.look.m);
    obj.mesh = f.mesh.value_or(0);
    loc = ObjectLoc{file, st.line(), st.where().column};
}

void Parser::one_pass_shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind) {
    const std::uint32_t file = file_index(st.file());
    Object obj;
    ObjectLoc loc;
    const std::optional<Arg> name = shape(st, toks, kind, file, scene_materials_, obj, loc);
    if (name) name_thing(st.file(), st.line(), *name, Named::Object, std::uint32_t(scene.objects.size()));
    scene.objects.push_back(obj);
    scene.object_locs.push_back(loc);
    for (const auto& [o, l] : extra_objects_) {  // materials=obj: the file's other parts
        scene.objects.push_back(o);
        scene.object_locs.push_back(l);
    }
    extra_objects_.clear();
}

std::uint32_t Parser::file_index(const std::string& file) {
    if (!scene.files.empty() && scene.files[last_file_] == file) return last_file_;
    for (std::uint32_t i = 0; i < scene.files.size(); ++i)
        if (scene.files[i] == file) return last_file_ = i;
    scene.files.push_back(file);
    return last_file_ = std::uint32_t(scene.files.size() - 1);
}

std::optional<Arg> Parser::shape(Statement& st, const std::vector<Token>& toks, ShapeKind kind, std::uint32_t file,
                         MaterialList& materials, Object& out, ObjectLoc& loc, const CsgBlock* within) {
    st.read_args(toks, 1, shape_keys(kind));
    ShapeFields f;
    f.kind = kind;
    if (within) f.look = within->look;
    const ShapeParam param = shape_param(kind);
    f.param = param.default_value;
    if (const Arg* base = st.find("material")) f.look = lookup_material(st, *base);
    const Arg* file_arg = nullptr;  // a mesh's file, read once the texture is known
    bool obj_materials = false;     // materials=obj: the file's own materials, a part each
    for (const Arg& a : st.args) {
        if (same(a.key, "material") || same(a.key, "name")) continue;
        if (material_key(st, a, f.look)) continue;
        if (apply_transform_key(st, a, f.md)) continue;
        if (param.present() && same(a.key, param.key)) f.param = st.positive(a);
        else if (same(a.key, "smooth")) f.smooth = st.boolean(a);
        else if (same(a.key, "file")) {
            file_arg = &a;
        } else if (same(a.key, "materials")) {
            if (!same(a.value, "obj"))
                st.fail(a.value_col, "expected obj for 'materials' (the OBJ file's own materials), got " +
                                         quote(a.value));
            obj_materials = true;
        }
    }
    if (f.look.m.vertex_colors) {
        // At the key, or at material= when the material brought it.
        const Arg* at = st.find("vertex_colors");
        if (!at) at = st.find("material");
        const int col = at ? at->key_col : st.where().column;
        if (kind != ShapeKind::Mesh)
            st.fail(col, "vertex_colors=true needs a mesh whose file colours its vertices, not a " +
                             std::string(st.word()));
        if (f.look.m.texture >= 0)
            st.fail(col, "vertex_colors=true and texture= both replace the object's colour: give one of them");
    }
    if (file_arg && obj_materials) {
        if (is_ply_path(std::string(file_arg->value)))
            st.fail(file_arg->value_col, "materials=obj needs an OBJ file (a PLY file has no material library), got " +
                                             quote(file_arg->value));
        if (f.look.m.vertex_colors)
            st.fail(file_arg->value_col, "vertex_colors=true and materials=obj both give the object's colour: give "
                                         "one of them");
        if (singular(f.md))
            st.fail_here(std::string(st.word()) + ": the composed transform is singular (or not finite)");
        // One object per part (usemtl group), each with its part's material over the
        // statement's; the first goes into `out`, the others after it (one-pass reader only:
        // mesh statements are never read in chunks).
        const ObjParts& parts = obj_parts(st, *file_arg, f.look.m.texture >= 0);
        for (std::size_t k = 0; k < parts.meshes.size(); ++k) {
            ShapeFields g = f;
            g.mesh = parts.meshes[k];
            apply_obj_material(st, *file_arg, parts, parts.materials[k], g.look);
            if (k == 0) {
                make_object(st, g, file, materials, out, loc);
            } else {
                extra_objects_.emplace_back();
                make_object(st, g, file, materials, extra_objects_.back().first, extra_objects_.back().second);
            }
        }
        if (const Arg* n = st.find("name")) return *n;
        return std::nullopt;
    }
    if (file_arg) f.mesh = mesh_file(st, *file_arg, f.look.m.texture >= 0, f.look.m.vertex_colors);
    if (kind == ShapeKind::Mesh && !f.mesh) st.fail_here("mesh needs 'file=PATH' (a Wavefront OBJ or PLY file)");
    if (within) f.md = within->md * f.md;
    if (singular(f.md))
        st.fail_here(std::string(st.word()) +
                     ": the composed transform is singular (or not finite)");
    make_object(st, f, file, materials, out, loc);
    if (const Arg* n = st.find("name")) return *n;
    return std::nullopt;
}

fs::path Parser::target_of(const Statement& st, const Arg& a) {
    return (fs::path(st.file()).parent_path() / fs::path(std::string(a.value))).lexically_normal();
}

std::uint32_t Parser::mesh_file(const Statement& st, const Arg& a, bool with_uv, bool with_colors) {
    constexpr std::string_view kMemory = "memory:";
    if (options_.memory_meshes && a.value.substr(0, kMemory.size()) == kMemory) {
        // A mesh held by the front end, added to the scene once (its texture coordinates, if
        // any, are those it was built with).
        const auto k = to_number(a.value.substr(kMemory.size()));
        const std::size_t n = options_.memory_meshes->size();
        if (!k || *k != std::floor(*k) || !(*k >= 0 && *k < double(n)))
            st.fail(a.value_col, "no in-memory mesh " + quote(a.value) + " (there are " + std::to_string(n) + ")");
        if (with_colors && !(*options_.memory_meshes)[std::size_t(*k)]->view().vertex_colors)
            st.fail(a.value_col, "vertex_colors=true needs colours at the vertices, and in-memory mesh " + quote(a.value) +
                                     " was made without them (Scene.mesh(..., colors=...))");
        const auto [it, added] = memory_mesh_index_.try_emplace(std::size_t(*k), std::uint32_t(scene.meshes.size()));
        if (added) scene.meshes.push_back((*options_.memory_meshes)[std::size_t(*k)]);
        return it->second;
    }
    return read_once(
        st, a.value_col, target_of(st, a), "mesh", meshes_, scene.meshes,
        [&](fs::path id) { return std::tuple{std::move(id), with_uv, with_colors}; },
        [&](const std::string& path) { return load_mesh_file(path, with_uv, with_colors); });
}

std::int32_t Parser::texture_file(const Statement& st, int col, const fs::path& target) {
    std::lock_guard<std::mutex> lock(textures_mutex_);
    return read_once(
        st, col, target, "texture", textures_, scene.textures, [](fs::path id) { return id; },
        [](const std::string& path) { return load_texture(path); });
}

const Parser::ObjParts& Parser::obj_parts(const Statement& st, const Arg& a, bool with_uv) {
    const std::size_t i = read_once(
        st, a.value_col, target_of(st, a), "mesh", obj_models_, obj_parts_,
        [&](fs::path id) { return std::pair{std::move(id), with_uv}; },
        [&](const std::string& path) {
            ObjModel model = load_obj_model(path, with_uv);
            ObjParts parts;
            for (ObjModel::Part& p : model.parts) {
                parts.meshes.push_back(std::uint32_t(scene.meshes.size()));
                scene.meshes.push_back(std::move(p.mesh));
                parts.materials.push_back(p.material);
            }
            parts.library = std::move(model.materials);
            parts.mtl_path = model.mtl_path;
            if (options_.copies && !parts.mtl_path.empty()) copy_file(parts.mtl_path);
            if (!parts.mtl_path.empty()) record_input(parts.mtl_path, "material library", st, a.value_col);
            return parts;
        });
    return obj_parts_[i];
}

void Parser::apply_obj_material(const Statement& st, const Arg& file, const Parser::ObjParts& parts, int material,
                        Appearance& look) {
    if (material < 0) return;
    const ObjMaterial& o = parts.library[std::size_t(material)];
    look.color = {o.kd[0], o.kd[1], o.kd[2]};
    look.m.spec = std::max(0.0, (o.ks[0] + o.ks[1] + o.ks[2]) / 3.0);
    look.m.shininess = std::max(0.0, o.ns);
    look.m.ior = o.ni > 0.0 ? o.ni : 1.0;
    look.m.trans = std::clamp(1.0 - o.d, 0.0, 1.0);
    if (!o.map_kd.empty())
        look.m.texture = texture_file(
            st, file.value_col, (fs::path(parts.mtl_path).parent_path() / fs::path(o.map_kd)).lexically_normal());
}

void Parser::copy_file(const fs::path& p) {
    FileText text;
    options_.copies->push_back(FileCopy{p.string(), text.open(p) ? std::string(text.text()) : std::string()});
}

void Parser::include(Statement& st, const std::vector<Token>& toks, int depth) {
    const Token& t = single_value(st, toks, "a file path");
    // A NUL would make the file opened differ from the file named (the OS stops at it);
    // no control byte belongs in a path here.
    for (const char c : t.text)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
            st.fail(t.column, "include path " + quote(t.text) + " contains a control byte");
    const fs::path base = fs::path(st.file()).parent_path();
    const fs::path target = (base / fs::path(std::string(t.text))).lexically_normal();
    const std::string shown = target.string();
    if (depth + 1 > kMaxIncludeDepth)
        st.fail(t.column, "includes nested deeper than " + std::to_string(kMaxIncludeDepth) +
                              " levels at " + quote(shown));
    if (files_ + 1 > kMaxFiles)
        st.fail(t.column, "more than " + std::to_string(kMaxFiles) +
                              " files read through include at " + quote(shown));
    const fs::path id = identity_of(target);
    if (std::find(open_.begin(), open_.end(), id) != open_.end())
        st.fail(t.column, "include cycle: " + quote(shown) + " is already being read");
    FileText text;
    if (!text.open(target)) st.fail(t.column, "cannot open included file " + quote(shown));
    if (options_.copies) options_.copies->push_back(FileCopy{shown, std::string(text.text())});
    record_input(shown, "included file", st, t.column);
    read_text(text.text(), shown, id, depth + 1);
}

}  // namespace streamrt::scene_reader
