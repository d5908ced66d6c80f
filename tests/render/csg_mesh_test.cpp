// A closed mesh as a CSG solid (docs/scene-format.md, "CSG"; mesh/mesh_solid.h): the reader's
// closedness check and its messages, and the recursive engine's spans of a mesh, against the
// canonical cube the mesh cube is made to match.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>

#include "baseline/recursive_renderer.h"
#include "driver/render.h"
#include "parallel/parallelism.h"
#include "scene/expect_error.h"
#include "render/csg_cases.h"
#include "scene/parser.h"

using namespace streamrt;
using csg_cases::hit_of;
namespace fs = std::filesystem;

namespace {


// The cube [-1,1]^3 as 12 triangles, counter-clockwise seen from outside (OBJ numbers from 1).
const char* const kCubeVertices =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";
const char* const kCubeFaces[12] = {"1 4 3", "1 3 2", "5 6 7", "5 7 8", "1 2 6", "1 6 5",
                                    "4 8 7", "4 7 3", "1 5 8", "1 8 4", "2 3 7", "2 7 6"};

/// A folder of this test's files: the cube, the cube with its last face left out (open), with
/// a face turned over (flipped), with every face turned over (inside out).
fs::path mesh_dir() {
    const fs::path dir = fs::temp_directory_path() / ("streamrt_csg_mesh_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const auto write = [&](const char* name, int leave_out, bool flip_one, bool flip_all) {
        std::ofstream f(dir / name);
        f << kCubeVertices;
        for (int k = 0; k < 12; ++k) {
            if (k == leave_out) continue;
            std::string face = kCubeFaces[k];
            if ((flip_one && k == 0) || flip_all) std::swap(face[2], face[4]);  // "a b c" -> "a c b"
            f << "f " << face << "\n";
        }
    };
    write("cube.obj", -1, false, false);
    write("open.obj", 11, false, false);
    write("flipped.obj", -1, true, false);
    write("inside_out.obj", -1, false, true);
    return dir;
}

Scene parse_in(const fs::path& dir, const std::string& text) { return parse_scene(text, (dir / "t.cfg").string()); }

/// The pixels of `a` with a channel more than `tol` from `b`'s, and the pixels `b` covers
/// (a channel above 0: not the black background).
std::pair<int, int> pixels_apart(const Framebuffer& a, const Framebuffer& b, float tol) {
    REQUIRE(a.width == b.width);
    REQUIRE(a.height == b.height);
    int differ = 0, covered = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            bool d = false, any = false;
            for (int c = 0; c < 3; ++c) {
                d = d || std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]) > tol;
                any = any || b.pixel(x, y)[c] > 0.f;
            }
            differ += d;
            covered += any;
        }
    return {differ, covered};
}


}  // namespace

TEST_CASE("csg mesh: a mesh in a csg block must close a volume, said at its file= value") {
    const fs::path dir = mesh_dir();
    const std::string path = (dir / "t.cfg").string();
    test::expect_error_in(path, "csg union\n  sphere\n  mesh file=open.obj\nend\n", 3, 13,
                          "'open.obj' does not: its edge (1, -1, -1) - (1, -1, 1) belongs to one triangle only");
    test::expect_error_in(path, "csg union\n  sphere\n  mesh file=flipped.obj\nend\n", 3, 13,
                          "is run along the same way by two triangles");
    test::expect_error_in(path, "csg union\n  sphere\n  mesh file=cube.obj materials=obj\nend\n", 3, 22,
                          "materials=obj cannot be used in a csg block");
    // A mesh counts as 8 shapes against the 64 of an object: 8 meshes fit, a 9th does not.
    std::string eight = "csg union\n";
    for (int k = 0; k < 8; ++k) eight += "  mesh file=cube.obj\n";
    CHECK(parse_in(dir, eight + "end\n").csg_shapes.size() == 8);
    test::expect_error_in(path, eight + "  sphere\nend\n", 10, 3, "a mesh counting as 8");
    // Outside a block an open mesh is a surface like any other.
    CHECK(parse_in(dir, "mesh file=open.obj\n").objects.size() == 1);
}

TEST_CASE("csg mesh: the mesh cube minus a sphere is hit where the canonical cube minus it is") {
    const fs::path dir = mesh_dir();
    for (const char* base : {"mesh file=cube.obj", "mesh file=inside_out.obj", "cube"}) {
        CAPTURE(base);
        const Scene s = parse_in(dir, std::string("csg difference\n  ") + base + "\n  sphere scale=1.3\nend\n");
        HitD hit;
        // Down the axis the sphere (radius 1.3 > 1) has removed all the cube there.
        CHECK(!hit_of(s, {0, 0, 5}, {0, 0, -1}, hit));
        // Near a corner the sphere is missed (0.95^2 + 0.95^2 > 1.3^2): the face z = 1, and out
        // of the cube at z = -1.
        REQUIRE(hit_of(s, {0.95, 0.95, 5}, {0, 0, -1}, hit));
        CHECK(hit.t == doctest::Approx(4.0).epsilon(1e-12));
        CHECK(hit.normal.z == doctest::Approx(1.0).epsilon(1e-12));
        REQUIRE(hit_of(s, {0.95, 0.95, 5}, {0, 0, -1}, hit, hit.t + 1e-9));
        CHECK(hit.t == doctest::Approx(6.0).epsilon(1e-12));
        // At x = 0.9 the face z = 1, then the sphere's wall at z = sqrt(1.69 - 0.81) = 0.938,
        // facing into the cavity (toward the sphere's centre).
        REQUIRE(hit_of(s, {0.9, 0, 5}, {0, 0, -1}, hit));
        CHECK(hit.t == doctest::Approx(4.0).epsilon(1e-12));
        REQUIRE(hit_of(s, {0.9, 0, 5}, {0, 0, -1}, hit, hit.t + 1e-9));
        const double z = std::sqrt(1.69 - 0.81);
        CHECK(hit.t == doctest::Approx(5.0 - z).epsilon(1e-12));
        CHECK(hit.normal.x == doctest::Approx(-0.9 / 1.3).epsilon(1e-9));
        CHECK(hit.normal.z == doctest::Approx(-z / 1.3).epsilon(1e-9));
    }
}

TEST_CASE("csg mesh: a line through the diagonals of the mesh cube's faces crosses each face once") {
    // x = y = 0.5 lies on the diagonal that splits the faces z = 1 and z = -1 into two triangles:
    // the watertight test counts the crossing on one of them, so the cube's span is [4, 6].
    const Scene s = parse_in(mesh_dir(), "csg intersection\n  mesh file=cube.obj\n  sphere scale=10\nend\n");
    HitD hit;
    REQUIRE(hit_of(s, {0.5, 0.5, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == doctest::Approx(4.0).epsilon(1e-12));
    REQUIRE(hit_of(s, {0.5, 0.5, 5}, {0, 0, -1}, hit, hit.t + 1e-9));
    CHECK(hit.t == doctest::Approx(6.0).epsilon(1e-12));
    CHECK(!hit_of(s, {0.5, 0.5, 5}, {0, 0, -1}, hit, hit.t + 1e-9));
    // Through the cube's corner-to-corner edge x = y = 1 of the faces x = 1 and y = 1, from
    // inside the sphere: in at z = 1, out at z = -1, nothing else.
    REQUIRE(hit_of(s, {1, 1, 5}, {0, 0, -1}, hit));
    CHECK(hit.t == doctest::Approx(4.0).epsilon(1e-12));
}

TEST_CASE("csg mesh: the mesh cube minus a sphere gives the canonical cube's picture, both engines") {
    // The cube inside out too: its triangles face in, so its surfaces' normals are turned
    // round at both ends of its spans (CsgSlotEnds::turned); the picture must not change. In
    // glass, so that a normal facing the wrong way bends the rays the wrong way (a lit opaque
    // surface would look the same from either side).
    const fs::path dir = mesh_dir();
    for (const EngineKind engine : {EngineKind::Recursive, EngineKind::Stream}) {
        const auto picture = [&](const char* base) {
            const std::string text =
                std::string("image width=48 height=36 degree=5\ncamera eye=3,2.5,4 look=0,0,0 fov=40\n"
                            "light point pos=5,8,6\nplane translate=0,-1.5,0 checker=0.2,0.2,0.2\n"
                            "csg difference color=0.8,0.5,0.2 refl=0.1 trans=0.8 ior=1.45\n  ") +
                base + "\n  sphere scale=1.3 color=0.2,0.5,0.9\nend\n";
            Parallelism par(1);
            return render_scene(parse_in(dir, text), engine, par).image;
        };
        const Framebuffer canonical = picture("cube");
        for (const char* base : {"mesh file=cube.obj", "mesh file=inside_out.obj"}) {
            const std::string base_name = base;
            CAPTURE(base_name);
            CAPTURE(int(engine));
            const Framebuffer mesh = picture(base);
            const auto [differ, covered] = pixels_apart(mesh, canonical, 1e-4f);
            // The same surfaces, lit alike; only a few pixels along edges, where the mesh's
            // and the cube's rounding send a refracted ray the other way, may differ (5 of
            // 1,728 on each engine; a normal facing the wrong way: hundreds).
            CHECK(differ <= 8);
            CHECK(covered > 300);  // not a picture of nothing
        }
    }
}

TEST_CASE("csg mesh: one file serves a plain mesh and CSG children, instances of the same triangles") {
    const fs::path dir = mesh_dir();
    const std::string objects =
        "mesh file=cube.obj translate=-2.5,0,0\n"
        "csg difference\n  mesh file=cube.obj\n  sphere scale=1.3\nend\n"
        "csg intersection translate=2.5,0,0\n  mesh file=./cube.obj scale=0.9\n  sphere scale=1.2\nend\n";
    const Scene s = parse_in(dir, objects);
    // Read once: the plain object and both CSG children point at the same triangles.
    REQUIRE(s.meshes.size() == 1);
    REQUIRE(s.csg_shapes.size() == 4);
    CHECK(s.objects[0].mesh == 0);
    CHECK(s.csg_shapes[0].mesh == 0);
    CHECK(s.csg_shapes[2].mesh == 0);
    // Each placed by its own Md: the plain cube's face z = 1; nothing down the difference's axis
    // (the sphere holds the cube there); the intersection's face z = 0.9, normal +z.
    HitD h;
    REQUIRE(hit_of(s, {-2.5, 0, 5}, {0, 0, -1}, h));
    CHECK(h.t == doctest::Approx(4.0).epsilon(1e-12));
    CHECK(!hit_of(s, {0, 0, 5}, {0, 0, -1}, h));
    REQUIRE(hit_of(s, {2.5, 0, 5}, {0, 0, -1}, h));
    CHECK(h.t == doctest::Approx(4.1).epsilon(1e-12));
    CHECK(h.normal.z == doctest::Approx(1.0).epsilon(1e-12));
    // The stream engine sees the same three objects.
    const Scene lit = parse_in(dir, "image width=64 height=24 degree=5\ncamera eye=0,2,9 look=0,0,0 fov=40\n"
                                    "light point pos=5,8,6\n" + objects);
    Parallelism par(1);
    const Framebuffer stream = render_scene(lit, EngineKind::Stream, par).image;
    const Framebuffer recursive = render_scene(lit, EngineKind::Recursive, par).image;
    const auto [differ, covered] = pixels_apart(stream, recursive, 1e-3f);
    CHECK(differ <= 2);
    CHECK(covered > 150);  // the three objects cover 185 of the 1,536 pixels
}
