// The scene reader's csg blocks (docs/scene-format.md, "CSG"): the tree it builds, what
// children inherit from their block, and each refusal at its exact line and column.
#include <doctest/doctest.h>

#include <glm/glm.hpp>

#include <string>

#include "scene/expect_error.h"
#include "scene/parser.h"
#include "scene/scene.h"

using namespace streamrt;
using test::expect_error;

namespace {

Scene parse(const std::string& text) { return parse_scene(text, "t.cfg"); }

glm::dvec3 world_point(const Object& o, const glm::dvec3& canonical) {
    return glm::dvec3(o.direct() * glm::dvec4(canonical, 1.0));
}

}  // namespace

TEST_CASE("csg parser: a difference of two cylinders is one object of two shapes") {
    const Scene s = parse(
        "csg difference translate=0,1,0\n"
        "  cylinder scale=1,2,1\n"
        "  cylinder scale=0.8,2.1,0.8\n"
        "end\n"
        "sphere\n");
    REQUIRE(s.csg_objects.size() == 1);
    CHECK(s.objects.size() == 1);  // the sphere alone: the block's shapes are not plain objects
    REQUIRE(s.csg_nodes.size() == 1);
    const CsgNode& node = s.csg_nodes[s.csg_objects[0].root];
    CHECK(node.op == CsgOp::Difference);
    REQUIRE(node.children.size() == 2);
    CHECK(!node.children[0].is_node);
    CHECK(!node.children[1].is_node);
    REQUIRE(s.csg_shapes.size() == 2);
    CHECK(s.csg_shapes[0].kind == ShapeKind::Cylinder);
    // The child's scale, then the block's translation: the canonical top rim (1,1,0) lands at (1,3,0).
    const glm::dvec3 rim = world_point(s.csg_shapes[node.children[0].index], {1, 1, 0});
    CHECK(rim.x == doctest::Approx(1.0));
    CHECK(rim.y == doctest::Approx(3.0));
    CHECK(rim.z == doctest::Approx(0.0));
    const glm::dvec3 inner = world_point(s.csg_shapes[node.children[1].index], {1, 1, 0});
    CHECK(inner.x == doctest::Approx(0.8));
    CHECK(inner.y == doctest::Approx(3.1));
    CHECK(s.csg_where(0).line == 1);
    CHECK(s.csg_where(0).column == 1);
}

TEST_CASE("csg parser: nested blocks compose their transforms, innermost first") {
    const Scene s = parse(
        "csg union translate=10,0,0\n"
        "  sphere\n"
        "  csg intersection scale=2,2,2\n"
        "    cube translate=0,1,0\n"
        "    sphere\n"
        "  end\n"
        "end\n");
    REQUIRE(s.csg_objects.size() == 1);
    REQUIRE(s.csg_nodes.size() == 2);
    const CsgNode& root = s.csg_nodes[s.csg_objects[0].root];
    CHECK(root.op == CsgOp::Union);
    REQUIRE(root.children.size() == 2);
    REQUIRE(root.children[1].is_node);
    const CsgNode& inner = s.csg_nodes[root.children[1].index];
    CHECK(inner.op == CsgOp::Intersection);
    REQUIRE(inner.children.size() == 2);
    // The cube's centre: moved up 1, scaled by 2 (to y = 2), then moved 10 along x.
    const glm::dvec3 c = world_point(s.csg_shapes[inner.children[0].index], {0, 0, 0});
    CHECK(c.x == doctest::Approx(10.0));
    CHECK(c.y == doctest::Approx(2.0));
    CHECK(c.z == doctest::Approx(0.0));
}

TEST_CASE("csg parser: a child's material keys are its own, the block's fill in what it does not give") {
    const Scene s = parse(
        "material glass trans=0.9 ior=1.5\n"
        "csg merge material=glass color=0,0,1\n"
        "  sphere\n"
        "  sphere translate=1,0,0 color=1,0,0\n"
        "  sphere translate=2,0,0 refl=0.5\n"
        "end\n");
    REQUIRE(s.csg_shapes.size() == 3);
    const Object& plain = s.csg_shapes[0];
    const Object& red = s.csg_shapes[1];
    const Object& mirror = s.csg_shapes[2];
    CHECK(plain.color == glm::vec3(0, 0, 1));
    CHECK(s.material_of(plain).trans == doctest::Approx(0.9));
    CHECK(s.material_of(plain).ior == doctest::Approx(1.5));
    CHECK(red.color == glm::vec3(1, 0, 0));
    CHECK(s.material_of(red).trans == doctest::Approx(0.9));
    CHECK(mirror.color == glm::vec3(0, 0, 1));
    CHECK(s.material_of(mirror).refl == doctest::Approx(0.5));
    CHECK(s.material_of(mirror).trans == doctest::Approx(0.9));
}

TEST_CASE("csg parser: every refusal at its line and column") {
    // The operation.
    expect_error("csg\nend", 1, 1, "expected union, intersection, difference or merge after 'csg'");
    expect_error("csg subtract\n sphere\n sphere\nend", 1, 5, "got 'subtract'");
    expect_error("csg scale=2\nend", 1, 5, "after 'csg'");
    // A missing end: at the block it leaves open (the innermost).
    expect_error("sphere\ncsg union\n  sphere\n", 2, 1, "csg union block has no 'end'");
    expect_error("csg union\n  sphere\n  csg intersection\n    sphere\nend\n", 1, 1, "has no 'end'");
    expect_error("csg union\n  sphere\n  csg intersection\n    sphere\n", 3, 3, "csg intersection block has no 'end'");
    // An end with no block, or with something after it.
    expect_error("sphere\n  end\n", 2, 3, "'end' with no csg block to end");
    expect_error("csg union\n sphere\nend union\n", 3, 5, "unexpected 'union' after 'end'");
    // An empty block; a difference of one child.
    expect_error("csg union\nend\n", 1, 1, "empty csg union block");
    expect_error("csg union\n  sphere\n  csg merge\n  end\nend\n", 3, 3, "empty csg merge block");
    expect_error("csg difference\n  sphere\nend\n", 1, 1, "csg difference needs at least two children");
    // Children without an inside; a torus whose tube overlaps itself (at its minor= value).
    expect_error("csg union\n  sphere\n  disk\nend\n", 3, 3, "a disk has no inside");
    expect_error("csg union\n  sphere\n  torus scale=2 minor=1.5\nend\n", 3, 23,
                 "a torus in a csg block needs minor <= 1 (a thicker tube overlaps itself: its inner surface bounds no "
                 "solid), got 1.5");
    expect_error("csg union\n  sphere name=ball\nend\n", 2, 10, "takes no name=");
    expect_error("csg union\n  light point pos=0,0,0\nend\n", 2, 3, "'light' cannot be inside a csg block");
    // Keys a block does not take, and a child's own key checks.
    expect_error("csg union smooth=true\n sphere\nend\n", 1, 11, "unknown key 'smooth' for 'csg'");
    expect_error("csg union\n  sphere colr=1,0,0\nend\n", 2, 10, "unknown key 'colr' for 'sphere'");
    expect_error("csg union scale=0,1,1\n sphere\nend\n", 1, 17, "scale components must be non-zero");
    expect_error("csg union material=steel\n sphere\nend\n", 1, 20, "unknown material 'steel'");
}

TEST_CASE("csg parser: a block ends in the file that opens it") {
    // In one text, a block of a large (chunked) read still reads in order: the chunked reader
    // falls back to one pass for csg.
    ReadOptions options;
    options.chunked_from = 1;
    options.chunk_bytes = 8;
    const Scene s = parse_scene("sphere\ncsg union\n sphere\n cube\nend\ncube\n", "t.cfg", options);
    CHECK(s.objects.size() == 2);
    CHECK(s.csg_shapes.size() == 2);
    REQUIRE(s.csg_objects.size() == 1);
}

TEST_CASE("csg parser: an object holds at most 64 shapes, nested blocks included") {
    std::string text = "csg union\n  csg union\n";
    for (int i = 0; i < 64; ++i) text += "    sphere\n";
    CHECK(parse(text + "  end\nend\n").csg_shapes.size() == 64);
    expect_error(text + "  cube\n  end\nend\n", 67, 3,
                 "a csg object holds at most 64 shapes, a mesh counting as 8 and a torus as 2 (its block is at t.cfg:1:1)");
    // A torus counts as two: 62 spheres and a torus fill an object, a sphere more is one too many.
    std::string tori = "csg union\n  torus minor=1\n";
    for (int i = 0; i < 62; ++i) tori += "  sphere\n";
    const Scene full = parse(tori + "end\n");
    CHECK(full.csg_shapes.size() == 63);
    CHECK(full.csg_shapes[0].kind == ShapeKind::Torus);
    CHECK(full.csg_shapes[0].param == 1.0);
    expect_error(tori + "  sphere\nend\n", 65, 3, "a csg object holds at most 64 shapes");
}
