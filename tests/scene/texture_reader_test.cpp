// The reader's texture keys (texture=, uvscale=) and the texture files behind them: sRGB
// decoding, sharing, and every refusal at its exact line:col; OBJ texture coordinates.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/srgb.h"
#include "mesh/mesh.h"
#include "render/texture.h"
#include "scene/parser.h"
#include "scene/expect_error.h"
#include "scene/test_png.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

struct Dir {
    fs::path dir;
    Dir() {
        static int counter = 0;
        dir = fs::temp_directory_path() /
              ("streamrt_texture_reader_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(dir);
        fs::create_directories(dir);
        test::write_png((dir / "quad.png").string(), 2, 2, test::kQuad);
        test::write_png_header_only((dir / "huge.png").string(), 80000, 80000);
        test::write_png_header_only((dir / "wide.png").string(), 20000, 2);
        std::ofstream(dir / "text.png") << "not an image\n";
        std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        std::ofstream(dir / "trivt.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
        // Two usemtl groups of one vertex list: a red glassy square, a textured one.
        std::ofstream(dir / "two.obj") << "mtllib two.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 3 -1 0\n"
                                          "v 3 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl red\nf 1 2 3\nf 1 3 4\n"
                                          "usemtl pic\nf 2/1 5/2 6/3\nf 2/1 6/3 3/4\n";
        std::ofstream(dir / "two.mtl") << "newmtl red\nKd 0.8 0.1 0.2\nKs 0.3 0.6 0.9\nNs 50\nNi 1.5\nd 0.75\n"
                                          "newmtl pic\nKd 1 1 1\nmap_Kd quad.png\n";
        std::ofstream(dir / "nolib.obj") << "mtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    }
    ~Dir() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    std::string cfg() const { return (dir / "t.cfg").string(); }
    Scene parse(const std::string& text) const { return parse_scene(text, cfg()); }
    void expect_error(const std::string& text, int line, int column, const std::string& needle) const {
        test::expect_error_in(cfg(), text, line, column, needle);
    }
};

}  // namespace

// Proven against: the sRGB table built with the 2.2 power law (128 gave 0.2195).
TEST_CASE("texture reader: texels are decoded from sRGB to linear") {
    // 128/255 = 0.50196: ((0.50196 + 0.055) / 1.055)^2.4 = 0.2158605 (IEC 61966-2-1).
    CHECK(srgb_to_linear(128) == doctest::Approx(0.2158605).epsilon(1e-6));
    // 10/255 = 0.039216 <= 0.04045: the linear segment, / 12.92 = 0.0030353.
    CHECK(srgb_to_linear(10) == doctest::Approx(0.0030352698).epsilon(1e-6));
    CHECK(srgb_to_linear(0) == 0.0f);
    CHECK(srgb_to_linear(255) == 1.0f);
}

// Proven against: textures not shared (read_once's lookup of a known file removed: each
// statement loaded its own, 2 textures).
TEST_CASE("texture reader: texture= and uvscale= on materials and shapes, one image per file") {
    Dir d;
    const Scene s = d.parse(
        "material tiled texture=quad.png uvscale=4\n"
        "sphere material=tiled\n"
        "plane texture=./quad.png\n"
        "cube color=0.5,0.5,0.5\n");
    REQUIRE(s.textures.size() == 1);
    const Texture& t = *s.textures[0];
    REQUIRE(t.levels.size() == 2);
    CHECK(t.levels[0].width == 2);
    // Top-left red, bottom-right white (codes 255 -> 1 exactly).
    CHECK(t.levels[0].rgb[0] == 1.0f);
    CHECK(t.levels[0].rgb[1] == 0.0f);
    CHECK(t.levels[0].rgb[9] == 1.0f);
    CHECK(s.material_of(s.objects[0]).texture == 0);
    CHECK(s.material_of(s.objects[0]).uv_scale == 4.0);
    CHECK(s.material_of(s.objects[1]).texture == 0);
    CHECK(s.material_of(s.objects[1]).uv_scale == 1.0);
    CHECK(s.material_of(s.objects[2]).texture == -1);
    CHECK(s.materials.size() == 3);
}

// Without load_texture's own PNG header read, the 80000 x 80000 file gave "unknown image
// type" (stb_image's header scan refuses it, then reports the last format it tried).
TEST_CASE("texture reader: missing, unreadable and too large images at the path's column") {
    Dir d;
    d.expect_error("sphere texture=nope.png\n", 1, 16, "cannot open texture file");
    d.expect_error("image width=4 height=4\nsphere color=1,1,1 texture=text.png\n", 2, 28,
                   "not a readable PNG or JPEG image");
    d.expect_error("material m texture=huge.png\n", 1, 20, "image of 80000 x 80000 texels is too large");
    d.expect_error("plane texture=wide.png\n", 1, 15, "at most 16384 per side");
    d.expect_error("sphere texture=quad.png uvscale=0\n", 1, 33, "'uvscale' must be > 0");
    d.expect_error("sphere texture=\n", 1, 16, "empty value");
}

// Proven against: the mesh read without its coordinates whatever the texture (mesh_file
// passing with_uv = false: no error, and the textured mesh had no uv).
TEST_CASE("texture reader: a textured mesh needs vt, coordinates kept only when a texture uses them") {
    Dir d;
    d.expect_error("mesh file=tri.obj texture=quad.png\n", 1, 11, "face without texture coordinates (vt)");
    const Scene s = d.parse(
        "mesh file=trivt.obj\n"
        "mesh file=trivt.obj texture=quad.png\n");
    REQUIRE(s.meshes.size() == 2);  // the untextured use is read without coordinates
    CHECK(s.meshes[s.objects[0].mesh]->view().uv == nullptr);
    const MeshView& m = s.meshes[s.objects[1].mesh]->view();
    REQUIRE(m.uv != nullptr);
    // Corners (0,0), (1,0), (0,1): at barycentrics (1/4, 1/2), (u, v) = (1/4, 1/2).
    const UvT<double> uv = mesh_uv(m, 0, 0.25, 0.5);
    CHECK(uv.u == doctest::Approx(0.25));
    CHECK(uv.v == doctest::Approx(0.5));
    // uv edge lengths 1 + sqrt2 + 1 over edge lengths 1 + sqrt2 + 1: density 1.
    CHECK(m.uv_density == doctest::Approx(1.0));
}

// Proven against: Ks mapped from its first component (spec 0.3, not the mean 0.6).
TEST_CASE("texture reader: mesh materials=obj maps each usemtl group's MTL material onto the keys") {
    Dir d;
    const Scene s = d.parse("mesh file=two.obj materials=obj ambi=0.5 scale=2\n");
    REQUIRE(s.objects.size() == 2);  // one object per usemtl group
    REQUIRE(s.meshes.size() == 2);
    const Material& red = s.material_of(s.objects[0]);
    CHECK(s.objects[0].color.x == doctest::Approx(0.8));  // Kd -> color
    CHECK(s.objects[0].color.z == doctest::Approx(0.2));
    CHECK(red.spec == doctest::Approx(0.6));        // Ks -> spec, the mean (0.3 + 0.6 + 0.9) / 3
    CHECK(red.shininess == doctest::Approx(50.0));  // Ns -> shininess
    CHECK(red.ior == doctest::Approx(1.5));         // Ni -> ior
    CHECK(red.trans == doctest::Approx(0.25));      // d -> trans = 1 - d
    CHECK(red.ambi == 0.5);                         // the statement's keys where MTL says nothing
    CHECK(red.texture == -1);
    CHECK(s.meshes[s.objects[0].mesh]->view().uv == nullptr);  // no map_Kd: no coordinates kept
    const Material& pic = s.material_of(s.objects[1]);
    REQUIRE(pic.texture == 0);  // map_Kd -> texture, relative to the library's folder
    CHECK(s.textures[0]->levels[0].width == 2);
    CHECK(s.meshes[s.objects[1].mesh]->view().uv != nullptr);
    CHECK(s.objects[0].md == s.objects[1].md);  // both placed by the statement
    d.expect_error("mesh file=two.obj materials=mtl\n", 1, 29, "expected obj for 'materials'");
    d.expect_error("mesh file=nolib.obj materials=obj\n", 1, 11, "cannot open material library");
}

// The chunked reader (shapes parsed in parallel, texture_file under its lock) shares one
// texture per file like the one-pass reader, and the copies hold the image's bytes (what the
// distributed renderer ships). Proven against: read_once without copy_file (0 bytes).
TEST_CASE("texture reader: chunked reading and file copies") {
    Dir d;
    std::string text;
    for (int i = 0; i < 200; ++i) text += "sphere texture=quad.png translate=" + std::to_string(i) + ",0,0\n";
    std::vector<FileCopy> copies;
    ReadOptions options;
    options.jobs = 2;
    options.chunk_bytes = 512;
    options.chunked_from = 0;
    options.copies = &copies;
    const Scene s = parse_scene(text, d.cfg(), options);
    CHECK(s.objects.size() == 200);
    CHECK(s.textures.size() == 1);
    CHECK(s.materials.size() == 1);
    std::size_t png_bytes = 0;
    for (const FileCopy& c : copies)
        if (c.path.find("quad.png") != std::string::npos) png_bytes = c.bytes.size();
    CHECK(png_bytes == fs::file_size(d.dir / "quad.png"));
}

// An 8 x 8 JPEG of sRGB grey 128 (ImageMagick, quality 100, 159 bytes): stb_image's JPEG
// decoder is in, and the texels are its linear value 0.2158605 (a flat block is coded
// exactly by its DC term: within one 8-bit code, 0.2122 .. 0.2195).
// Proven against: STBI_ONLY_JPEG removed from scene/texture.cpp ("unknown image type").
TEST_CASE("texture reader: a JPEG file") {
    static const unsigned char kGreyJpeg[] = {
    0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 0x4a, 0x46, 0x49, 0x46, 0x00, 0x01, 0x01, 0x00, 0x00, 0x01,
    0x00, 0x01, 0x00, 0x00, 0xff, 0xdb, 0x00, 0x43, 0x00, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
    0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
    0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
    0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
    0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0xff, 0xc0, 0x00, 0x0b, 0x08, 0x00, 0x08,
    0x00, 0x08, 0x01, 0x01, 0x11, 0x00, 0xff, 0xc4, 0x00, 0x14, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xff, 0xc4, 0x00, 0x14,
    0x10, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0xff, 0xda, 0x00, 0x08, 0x01, 0x01, 0x00, 0x00, 0x3f, 0x00, 0x3f, 0xff, 0xd9
    };
    Dir d;
    const fs::path path = d.dir / "grey.jpg";
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(kGreyJpeg), sizeof kGreyJpeg);
    const auto t = load_texture(path.string());
    REQUIRE(t->levels[0].width == 8);
    REQUIRE(t->levels[0].height == 8);
    for (int k = 0; k < 8 * 8 * 3; k += 37) {
        CHECK(t->levels[0].rgb[k] >= 0.2122f);
        CHECK(t->levels[0].rgb[k] <= 0.2195f);
    }
}
