// The scene reader's csg blocks (docs/scene-format.md, "CSG"): `csg OP keys...`, its children
// (shape statements and nested blocks, one a line) and `end`. A block's children are kept
// apart from Scene::objects, in world space, each with its own material.
#include <string>
#include <vector>

#include "core/format_number.h"
#include "mesh/mesh_solid.h"
#include "scene/parser_state.h"

namespace streamrt::scene_reader {

void Parser::csg(Statement& st, const std::vector<Token>& toks) {
    const std::string ops = names_list(kCsgOpNames);
    if (toks.size() < 2 || toks[1].text.find('=') != std::string_view::npos)
        st.fail(toks.size() < 2 ? toks[0].column : toks[1].column, "expected " + ops + " after 'csg'");
    const Arg op_arg{"csg", toks[1].column, toks[1].text, toks[1].column};
    CsgBlock block;
    block.node.op = st.word(op_arg, kCsgOpNames);
    st.read_args(toks, 2, kCsgKeys);
    // A nested block starts from its parent's appearance; its transform applies before the
    // parent's, as a child shape's does.
    if (!csg_blocks_.empty()) block.look = csg_blocks_.back().look;
    if (const Arg* base = st.find("material")) block.look = lookup_material(st, *base);
    glm::dmat4 own(1.0);
    for (const Arg& a : st.args) {
        if (same(a.key, "material") || same(a.key, "name") || material_key(st, a, block.look)) continue;
        apply_transform_key(st, a, own);
    }
    if (const Arg* name = st.find("name")) {
        // The outermost block is the object that keys move; it is the next CSG object.
        if (!csg_blocks_.empty())
            st.fail(name->key_col, "a nested csg block takes no name= (the outermost block is the object)");
        name_thing(st.file(), st.line(), *name, Named::Csg, std::uint32_t(scene.csg_objects.size()));
    }
    if (csg_blocks_.empty()) block.first_shape = std::uint32_t(scene.csg_shapes.size());
    if (singular(own)) st.fail_here("csg: the composed transform is singular (or not finite)");
    block.md = csg_blocks_.empty() ? own : csg_blocks_.back().md * own;
    block.at = st.where();
    block.file = file_index(st.file());
    csg_blocks_.push_back(std::move(block));
}

void Parser::csg_end(Statement& st, const std::vector<Token>& toks) {
    if (toks.size() > 1)
        st.fail(toks[1].column, "unexpected " + quote(toks[1].text) + " after 'end'");
    if (csg_blocks_.size() <= file_csg_base_) st.fail_here("'end' with no csg block to end");
    CsgBlock block = std::move(csg_blocks_.back());
    csg_blocks_.pop_back();
    const std::string op(name_of(kCsgOpNames, block.node.op));
    const auto fail_at_block = [&](const std::string& msg) { throw SceneError(block.at, msg); };
    if (block.node.children.empty())
        fail_at_block("empty csg " + op + " block: give it shapes or csg blocks, one a line, before 'end'");
    if (block.node.op == CsgOp::Difference && block.node.children.size() < 2)
        fail_at_block("csg difference needs at least two children (the first minus the others), got 1");
    const auto index = std::uint32_t(scene.csg_nodes.size());
    scene.csg_nodes.push_back(std::move(block.node));
    if (!csg_blocks_.empty()) {
        csg_blocks_.back().node.children.push_back({true, index});
        return;
    }
    scene.csg_objects.push_back({index, ObjectLoc{block.file, block.at.line, block.at.column}, block.first_shape,
                                 std::uint32_t(scene.csg_shapes.size()) - block.first_shape});
}

void Parser::csg_child(Statement& st, const std::vector<Token>& toks, ShapeKind kind) {
    if (kind == ShapeKind::Disk)
        st.fail_here("a disk has no inside, so it cannot be part of a csg block (a thin cylinder has one)");
    if (kind != ShapeKind::Mesh && !shape_is_solid(kind))
        st.fail_here("a " + std::string(st.word()) + " cannot be part of a csg block (it has no inside)");
    // A shape a line may cross several times counts as the spans it may add (csg_slots_of).
    csg_blocks_.front().shapes += csg_slots_of(kind);
    if (csg_blocks_.front().shapes > kMaxCsgShapes)
        st.fail_here("a csg object holds at most " + std::to_string(kMaxCsgShapes) + " shapes, a mesh counting as " +
                     std::to_string(kMeshCsgSpans) + " and a torus as " +
                     std::to_string(csg_slots_of(ShapeKind::Torus)) + " (its block is at " +
                     csg_blocks_.front().at.str() + ")");
    CsgBlock& block = csg_blocks_.back();
    Object obj;
    ObjectLoc loc;
    if (const auto name = shape(st, toks, kind, block.file, scene_materials_, obj, loc, &block))
        st.fail(name->key_col, "a csg block's shape takes no name= (the block is the object)");
    if (kind == ShapeKind::Torus && obj.param > 1.0) {
        // Past minor = 1 the tube overlaps itself and the quartic's inner sheet lies inside
        // the solid: no surface of it.
        const Arg* minor = st.find("minor");
        st.fail(minor ? minor->value_col : st.where().column,
                "a torus in a csg block needs minor <= 1 (a thicker tube overlaps itself: its inner surface bounds no "
                "solid), got " + fmt_num(obj.param));
    }
    if (kind == ShapeKind::Mesh) {
        // materials=obj made an object of each part of the file: one solid is wanted.
        if (const Arg* m = st.find("materials"))
            st.fail(m->key_col, "materials=obj cannot be used in a csg block (each part of the file would be its own "
                                "object): give the mesh one material");
        check_closed_mesh(st, obj.mesh);
    }
    block.node.children.push_back({false, std::uint32_t(scene.csg_shapes.size())});
    scene.csg_shapes.push_back(obj);
}

void Parser::check_closed_mesh(const Statement& st, std::uint32_t mesh) {
    if (!closed_meshes_.insert(mesh).second) return;  // each mesh checked once
    const auto open = first_open_edge(*scene.meshes[mesh]);
    if (!open) return;
    const auto point = [](const std::array<float, 3>& p) {
        // Appended piece by piece: GCC 12 takes `"(" + std::string&&` for an overlapping copy
        // (a false -Wrestrict).
        std::string s = "(";
        s.append(fmt_num(p[0])).append(", ").append(fmt_num(p[1])).append(", ").append(fmt_num(p[2])).append(")");
        return s;
    };
    const Arg* file = st.find("file");
    const std::string edge = "its edge " + point(open->a) + " - " + point(open->b);
    const std::string why = open->same_direction ? edge + " is run along the same way by two triangles (one is turned over)"
                            : open->triangles == 1 ? edge + " belongs to one triangle only (a hole)"
                                                   : edge + " belongs to " + std::to_string(open->triangles) +
                                                         " triangles (surfaces meet there)";
    st.fail(file ? file->value_col : st.where().column,
            "a mesh in a csg block must close a volume (each edge shared by two triangles, oriented alike), and " +
                quote(file ? file->value : std::string_view("the mesh")) + " does not: " + why);
}

void Parser::check_csg_closed() const {
    if (csg_blocks_.size() > file_csg_base_)
        throw SceneError(csg_blocks_.back().at, "csg " + std::string(name_of(kCsgOpNames, csg_blocks_.back().node.op)) +
                                                    " block has no 'end' (one must end it in the same file)");
}

}  // namespace streamrt::scene_reader
