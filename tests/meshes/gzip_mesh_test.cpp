// Gzip-compressed mesh files (engine/mesh/mesh_bytes.h): `.ply.gz` and `.obj.gz` read as the
// plain files, errors at the inflated text's line and column, and bad compressed data refused
// with the byte where reading stopped.
#include <doctest/doctest.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "driver/render.h"
#include "error_of.h"
#include "meshes/gzip_member.h"
#include "mesh/mesh.h"
#include "mesh/mesh_bytes.h"
#include "mesh/ply_reader.h"
#include "parallel/parallelism.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

using streamrt::test::error_of;

namespace {

std::string gzip(const std::string& data) { return test::gzip_member(data); }

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

struct Dir {
    fs::path path = fs::temp_directory_path() / ("streamrt_gzip_test_" + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() { fs::remove_all(path); }
    void write(const std::string& name, const std::string& bytes) const {
        std::ofstream(path / name, std::ios::binary) << bytes;
    }
};

// A unit square in z = 0 as two triangles, and the same square with one bad face on line 7.
const char* kObj = "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
const char* kBadObj = "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 9\n";

}  // namespace

TEST_CASE("gzip: .ply.gz and .obj.gz meshes read and render as the plain files, members concatenated") {
    CHECK(is_gzip_path("a/b.ply.GZ"));
    CHECK_FALSE(is_gzip_path("a/b.ply"));
    CHECK(is_ply_path("bunny.PLY.gz"));
    CHECK_FALSE(is_ply_path("bunny.obj.gz"));
    CHECK(without_gzip_suffix("m.obj.gz") == "m.obj");

    Dir d;
    const std::string ply = slurp(fs::path(STREAMRT_SOURCE_DIR) / "scenes/meshes/colored_sphere.ply");
    REQUIRE(ply.size() > 1000);
    d.write("s.ply", ply);
    d.write("s.ply.gz", gzip(ply));
    // The OBJ in two gzip members, split mid-line: `cat a.gz b.gz` inflates to the whole.
    const std::string obj = std::string(kObj) + "f 2 3 4\n";
    d.write("q.obj", obj);
    d.write("q.obj.gz", gzip(obj.substr(0, 20)) + gzip(obj.substr(20)));

    const auto plain = load_mesh_file((d.path / "s.ply").string(), false, true);
    const auto packed = load_mesh_file((d.path / "s.ply.gz").string(), false, true);
    CHECK(packed->positions == plain->positions);
    CHECK(packed->index == plain->index);
    CHECK(packed->vertex_colors == plain->vertex_colors);
    CHECK(load_mesh_file((d.path / "q.obj.gz").string(), false)->triangle_count() == 3);

    const auto scene_with = [&](const std::string& ply_file, const std::string& obj_file) {
        return parse_scene("image width=48 height=36 spp=1 depth=2\ncamera eye=0,0.5,4 look=0,0,0\n"
                           "light point pos=3,6,4\nmesh file=" + ply_file + " smooth=true vertex_colors=true\n"
                           "mesh file=" + obj_file + " color=0.2,0.4,0.9 translate=-1.5,-1,0\n",
                           (d.path / "scene.cfg").string());
    };
    const Scene a = scene_with("s.ply", "q.obj"), b = scene_with("s.ply.gz", "q.obj.gz");
    Parallelism par(2);
    for (EngineKind e : {EngineKind::Stream, EngineKind::Recursive})
        CHECK(render_scene(a, e, par).image.rgb == render_scene(b, e, par).image.rgb);
}

TEST_CASE("gzip: errors at the inflated text's line and column, and corrupt, truncated or trailing data refused") {
    Dir d;
    d.write("bad.obj.gz", gzip(kBadObj));
    // Line 7, the face's third vertex number (9 of 4 vertices): what `zcat bad.obj.gz` shows.
    const std::string obj_error = error_of([&] { load_mesh_file((d.path / "bad.obj.gz").string(), false); });
    CHECK(obj_error.find("bad.obj.gz:7:7: ") != std::string::npos);

    const std::string good = gzip(std::string(kObj));
    const std::string where = (d.path / "t.obj.gz").string();
    const auto error_for = [&](const std::string& bytes) {
        d.write("t.obj.gz", bytes);
        return error_of([&] { load_mesh_file(where, false); });
    };
    CHECK(error_for(good.substr(0, good.size() - 6)) ==
          "gzip data ends early (a truncated file?) at byte " + std::to_string(good.size() - 6) +
              " of the compressed file");
    CHECK(error_for(good + "xyz") ==
          "data after the end of the gzip stream at byte " + std::to_string(good.size()) + " of the compressed file");
    CHECK(error_for(std::string(kObj)).rfind("corrupt gzip data (incorrect header check) at byte ", 0) == 0);
    std::string flipped = good;
    flipped[12] = char(flipped[12] ^ 0x55);  // inside the deflate data, after the 10-byte header
    CHECK(error_for(flipped).find("gzip data") != std::string::npos);
    CHECK(error_for("").find("gzip data ends early (a truncated file?) at byte 0 ") == 0);
    // More than the limit inflated: refused before it is held (zlib has read part of the input).
    CHECK(error_of([&] { inflate_gzip(good, 20); })
              .rfind("gzip data inflates past the memory budget of 20 bytes at byte ", 0) == 0);
    CHECK(inflate_gzip(good, 4096).size() == std::string(kObj).size());
    // In a scene: one line, the statement's path column first, then the reader's reason.
    d.write("t.obj.gz", good.substr(0, good.size() - 6));
    const std::string scene = (d.path / "s.cfg").string();
    const std::string e = error_of([&] { parse_scene("sphere\nmesh file=t.obj.gz\n", scene); });
    CHECK(e.rfind(scene + ":2:11: ", 0) == 0);
    CHECK(e.find("gzip data ends early (a truncated file?) at byte " + std::to_string(good.size() - 6)) !=
          std::string::npos);
    CHECK(e.find('\n') == std::string::npos);
}
