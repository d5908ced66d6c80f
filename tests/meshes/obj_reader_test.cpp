// The OBJ reader (engine/mesh/obj_reader.cpp) against tinyobjloader, the reader it replaced,
// kept here as the oracle (the engine's code before, read_obj_faces): files written here (quads
// cut along either diagonal, polygons ear-clipped, relative indices, every corner form,
// comments, blank lines, CRLF and CR line ends, no final newline, very long lines, usemtl
// groups) give the same positions, triangles, texture coordinates and meshes (normals
// included); the same data at every chunk size and thread count; every error at its
// file:line:col, the first in the file whatever the chunks.
#include <doctest/doctest.h>
#include <tiny_obj_loader.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "mesh/obj_reader.h"
#include "parallel/parallelism.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

struct TempDir {
    fs::path dir;
    TempDir() {
        static int counter = 0;
        dir = fs::temp_directory_path() / ("streamrt_obj_reader_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(dir / name, std::ios::binary) << text;
        return (dir / name).string();
    }
};

/// What tinyobjloader gave: the engine's reading before obj_reader (read_obj_faces), triangles
/// grouped by material id (-1 only unless by_material), corner uv where uv_for(group).
struct Oracle {
    std::vector<float> positions;
    struct Group {
        std::vector<std::uint32_t> tris;
        std::vector<float> corner_uv;
    };
    std::map<int, Group> groups;
    std::vector<tinyobj::material_t> materials;
};

Oracle oracle(const std::string& obj, const std::string& mtl, bool by_material, const std::function<bool(int)>& uv_for) {
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    REQUIRE_MESSAGE(reader.ParseFromString(obj, mtl, config), reader.Error());
    Oracle out;
    const tinyobj::attrib_t& at = reader.GetAttrib();
    out.positions.assign(at.vertices.begin(), at.vertices.end());
    out.materials = reader.GetMaterials();
    for (const tinyobj::shape_t& s : reader.GetShapes()) {
        std::size_t off = 0;
        for (std::size_t f = 0; f < s.mesh.num_face_vertices.size(); ++f) {
            REQUIRE(s.mesh.num_face_vertices[f] == 3);
            const int key = by_material ? s.mesh.material_ids[f] : -1;
            Oracle::Group& g = out.groups[key];
            for (int j = 0; j < 3; ++j) {
                const tinyobj::index_t& ix = s.mesh.indices[off + std::size_t(j)];
                REQUIRE(ix.vertex_index >= 0);
                g.tris.push_back(std::uint32_t(ix.vertex_index));
                if (!uv_for(key)) continue;
                REQUIRE(ix.texcoord_index >= 0);
                g.corner_uv.push_back(at.texcoords[2 * std::size_t(ix.texcoord_index)]);
                g.corner_uv.push_back(at.texcoords[2 * std::size_t(ix.texcoord_index) + 1]);
            }
            off += 3;
        }
    }
    return out;
}

/// tinyobjloader's vt numbers of every triangle corner (ObjData::kNoUv where none).
std::vector<std::uint32_t> oracle_uv_indices(const std::string& obj) {
    tinyobj::ObjReaderConfig config;
    tinyobj::ObjReader reader;
    REQUIRE(reader.ParseFromString(obj, "", config));
    std::vector<std::uint32_t> out;
    for (const tinyobj::shape_t& s : reader.GetShapes())
        for (const tinyobj::index_t& ix : s.mesh.indices)
            out.push_back(ix.texcoord_index < 0 ? ObjData::kNoUv : std::uint32_t(ix.texcoord_index));
    return out;
}

void check_same_mesh(const Mesh& a, const Mesh& b) {
    CHECK(a.triangle_count() == b.triangle_count());
    CHECK(a.dropped == b.dropped);
    CHECK(std::equal(a.positions.begin(), a.positions.end(), b.positions.begin(), b.positions.end()));
    CHECK(a.index == b.index);
    CHECK(a.vertex_normals == b.vertex_normals);
    CHECK(a.corner_uv == b.corner_uv);
}

/// The corners' texture coordinates of parse_obj's triangles (6 per triangle).
std::vector<float> corner_uv_of(const ObjData& d) {
    std::vector<float> uv;
    for (std::uint32_t t : d.triangle_uv) {
        REQUIRE(t != ObjData::kNoUv);
        uv.push_back(d.texcoords[2 * t]);
        uv.push_back(d.texcoords[2 * t + 1]);
    }
    return uv;
}

std::string with_line_ends(const std::string& text, const std::string& end) {
    std::string out;
    for (char c : text) {
        if (c == '\n') out += end;
        else out += c;
    }
    return out;
}

/// A 1 MB comment, numbers of hundreds of digits (exact in both readers), a 200-corner face.
std::string long_lines() {
    std::string t = "#" + std::string(1 << 20, 'x') + "\n";
    t += "v 0." + std::string(300, '0') + " " + std::string(300, '0') + "1.5 -0.25" + std::string(200, '0') + "\n";
    const int n = 200;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * 3.14159265358979 * i / n;
        t += "v " + std::to_string(std::round(std::cos(a) * 4096) / 4096) + " 0.5 " +
             std::to_string(std::round(std::sin(a) * 4096) / 4096) + "\n";
    }
    t += "f";  // relative: the same polygon wherever the text is put
    for (int i = 1; i <= n; ++i) t += " -" + std::to_string(i);
    return t + "\nf -201 -200 -199\n";
}

/// The files compared with tinyobjloader (none uses a case it read differently, see below).
std::vector<std::pair<std::string, std::string>> cases() {
    // Quads: 1 2 3 4 along 1-3 (the shorter diagonal), 2 5 6 3 along 5-3, the square 7 8 9 10
    // (a tie) along 8-10.
    const std::string quads = "# quads\n\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.25\nv 2 0 0\nv 2 1.5 0.5\n"
                              "v 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\nf 1 2 3\nf 1 2 3 4\nf 2 5 6 3\nf 7 8 9 10\n";
    const std::string relative = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 1\nf -1 -2 -3\n"
                                 "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 1 0\n"
                                 "f -4/-3/-1 -3/-2/-2 -2/-1/-1\nf 1/1 2/2 4/3\nf 2//1 3//2 4//1\nf 1/1/1 +2/+2/+2 3/3/1\n";
    const std::string blanks = "  # indented comment\n\t\n   \n v\t0 0 0 # a vertex\n\tv 1  0\t0\nv 0 1 0 1.0\n"
                               "v 1 1 0 0.5 0.25 0.125\nv -1.5e0 +.5 2.5E-1\no thing\ng part\ns off\nl 1 2\np 3\n"
                               "vp 0.5\ncstype bezier\nusemtl nothing\nf 1 2 3\n\n\nf   2\t 4 3  \nf 5 1 3\n";
    // Non-convex and tilted polygons for the ear clipping: a pentagon, an L, a star in xz,
    // one in yz whose first turn is straight, a non-planar one.
    const std::string polygons =
        "v 0 0 0\nv 2 0 0\nv 3 1.5 0\nv 1 3 0\nv -1 1.5 0\nf -5 -4 -3 -2 -1\n"
        "v 0 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\nf -6 -5 -4 -3 -2 -1\n"
        "v 0 0 0\nv 1 0 0.5\nv 2 0 0\nv 1.5 0 1\nv 2 0 2\nv 1 0 1.5\nv 0 0 2\nv 0.5 0 1\nf -8 -7 -6 -5 -4 -3 -2 -1\n"
        "v 5 0 0\nv 5 1 0\nv 5 2 0\nv 5 2 2\nv 5 1 1.5\nv 5 0 2\nf -6 -5 -4 -3 -2 -1\n"
        "v 0 0 3\nv 1 0 3.5\nv 2 1 3\nv 1 2 3.25\nv 0 1 3.5\nf -5 -4 -3 -2 -1\n";
    std::string sphere;  // %.9g numbers of a subdivided sphere
    {
        const fs::path p = fs::temp_directory_path() / ("streamrt_obj_reader_ico_" + std::to_string(::getpid()) + ".obj");
        REQUIRE(write_obj(p.string(), icosphere(3)));
        std::ifstream in(p, std::ios::binary);
        sphere.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        fs::remove(p);
    }
    return {{"quads", quads},
            {"relative", relative},
            {"blanks", blanks},
            {"crlf", with_line_ends(quads + relative, "\r\n")},
            {"cr", with_line_ends(blanks, "\r")},
            {"no_final_newline", quads + "f 3 4 1"},
            {"no_final_newline_crlf", with_line_ends(relative, "\r\n") + "f 1 2 3\r"},
            {"long_lines", long_lines()},
            {"polygons", polygons},
            {"sphere", sphere}};
}

/// An error's text, or "" when `bytes` parse.
std::string parse_error(const std::string& bytes, const ObjReadOptions& options = {}) {
    try {
        parse_obj(bytes, "m.obj", options);
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// Proven against: a quad fanned (0 1 2, 0 2 3) whatever its diagonals ("quads": 2 5 6 3
// differed), or split along 1-3 on a tie (the square); the ear clipper always projecting onto yz, or without its inside test, or used
// from 5 corners on only up to 4 ("polygons"); relative indices counted from the chunk's start
// ("relative" at chunk_bytes 16); relative vt counted with the vertices; '\r' not a line end.
TEST_CASE("obj reader: the positions, triangles, texture coordinates and meshes tinyobjloader gave") {
    TempDir d;
    for (const auto& [name, text] : cases()) {
        INFO("file ", name);
        const Oracle o = oracle(text, "", false, [](int) { return false; });
        const Oracle::Group& g = o.groups.count(-1) ? o.groups.at(-1) : Oracle::Group{};
        for (const std::size_t chunk : {std::size_t(1) << 20, std::size_t(16)}) {
            const ObjData data = parse_obj(text, name, {.keep_uv = chunk == 16, .chunk_bytes = chunk});
            CHECK(data.positions == o.positions);
            CHECK(data.triangles == g.tris);
            if (chunk == 16) CHECK(data.triangle_uv == oracle_uv_indices(text));
        }
        const std::string path = d.write(name + ".obj", text);
        check_same_mesh(*load_obj_mesh(path), *Mesh::build(path, o.positions, g.tris));
    }
    // With texture coordinates on every face.
    const std::string vt = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1 0\nvt 0.5\n"
                           "f 1/1 2/2 3/3 4/4\nf 2/2/1 5/5/1 3/3/1\nf -4/-4 -3/-3 -2/-2 -1/-1 -5/-5\nvn 0 0 1\n";
    const Oracle o = oracle(vt, "", false, [](int) { return true; });
    const ObjData data = parse_obj(vt, "vt.obj", {.keep_uv = true});
    CHECK(data.triangles == o.groups.at(-1).tris);
    CHECK(corner_uv_of(data) == o.groups.at(-1).corner_uv);
    CHECK(data.texcoords[2 * 4 + 1] == 0.f);  // vt 0.5: v defaults to 0
    CHECK(data.normal_count == 1);
    const std::string path = d.write("vt.obj", vt);
    check_same_mesh(*load_obj_mesh(path, true), *Mesh::build(path, o.positions, o.groups.at(-1).tris, {}, o.groups.at(-1).corner_uv));
}

// Where the reader differs from tinyobjloader on valid files, on purpose: where its ear
// clipping found no ear in a whole round (this self-crossing hexagon) it dropped the rest of
// the face; a face of more than 256 corners is fanned (ear clipping may take n^3 steps); a
// byte order mark hid the first line from it.
// Proven against: the fan fallback removed (1 triangle, as tinyobjloader); the mark kept.
TEST_CASE("obj reader: polygons tinyobjloader gave up on are fanned, very large ones too, a BOM is skipped") {
    const std::string text = "v -2 2 0\nv 3 -2 0\nv 1 1 0\nv 2 0 0\nv 1 3 0\nv -1 -2 0\nf 1 2 3 4 5 6\n";
    const Oracle o = oracle(text, "", false, [](int) { return false; });
    const ObjData data = parse_obj(text, "x.obj");
    REQUIRE(o.groups.at(-1).tris.size() == 3);  // one triangle, three of the hexagon's lost
    REQUIRE(data.triangles.size() == 12);
    CHECK(std::equal(o.groups.at(-1).tris.begin(), o.groups.at(-1).tris.end(), data.triangles.begin()));
    // Its ear (corners 6 1 2), then the rest (corners 2 to 6) fanned from its first corner.
    CHECK(data.triangles == std::vector<std::uint32_t>{5, 0, 1, 1, 2, 3, 1, 3, 4, 1, 4, 5});
    // A UTF-8 byte order mark: tinyobjloader skipped the first line (its vertex lost); read here.
    const ObjData bom = parse_obj("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "bom.obj");
    CHECK(bom.positions.size() == 9);
    CHECK(bom.triangles == std::vector<std::uint32_t>{0, 1, 2});
    CHECK(parse_error("\xEF\xBB\xBFv 0 x 0\n") == "m.obj:1:5: expected a vertex coordinate (v x y z), got 'x'");
    std::string big;
    for (int i = 0; i < 300; ++i) big += "v " + std::to_string(std::cos(i / 300.0 * 6.28318)) + " " + std::to_string(std::sin(i / 300.0 * 6.28318)) + " 0\n";
    big += "f";
    for (int i = 1; i <= 300; ++i) big += " " + std::to_string(i);
    const ObjData fan = parse_obj(big, "big.obj");
    REQUIRE(fan.triangles.size() == 3 * 298);
    for (std::uint32_t k = 0; k < 298; ++k) {
        CHECK(fan.triangles[3 * k] == 0);
        CHECK(fan.triangles[3 * k + 1] == k + 1);
        CHECK(fan.triangles[3 * k + 2] == k + 2);
    }
}

// Proven against: short_decimal multiplying by 1 / 10^k instead of dividing (not correctly
// rounded: some hundreds differ) and accepting 10 digits (m wraps).
TEST_CASE("obj reader: numbers are the correctly rounded floats std::from_chars gives") {
    std::vector<std::string> words = {"-0.000000", "5.", ".5", "-.5", "+.5", "+3", "16777216", "16777217", "0.16777217",
                                      "1677721.6", "1677721.7", "000123.4560", "9999999999", "0.0000000001", "1e-45",
                                      "3.4028234e38", "1234567.8", "0.999999999", "-7", "2.5e+3", "1E2"};
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const char* formats[] = {"%.6f", "%.3f", "%.9g", "%g", "%.4e", "%.0f", "%.10f", "%.7f"};
    for (int i = 0; i < 60000; ++i) {
        char b[64];
        std::snprintf(b, sizeof b, formats[i % 8], std::ldexp(unit(rng), int(rng() % 40) - 16));
        words.push_back(b);
    }
    while (words.size() % 3) words.push_back("0");
    std::string text;
    for (std::size_t k = 0; k < words.size(); k += 3) text += "v " + words[k] + " " + words[k + 1] + " " + words[k + 2] + "\n";
    const ObjData d = parse_obj(text, "n.obj");
    REQUIRE(d.positions.size() == words.size());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < words.size(); ++k) {
        const std::string& w = words[k];
        const char* b = w.data() + (w[0] == '+');
        float expected = 0;
        REQUIRE(std::from_chars(b, w.data() + w.size(), expected).ec == std::errc());
        if (d.positions[k] != expected || std::signbit(d.positions[k]) != std::signbit(expected)) {
            char msg[160];
            std::snprintf(msg, sizeof msg, "%s read as %.9g, from_chars gives %.9g", w.c_str(), d.positions[k], expected);
            if (differ++ == 0) FAIL_CHECK(msg);
        }
    }
    CHECK(differ == 0);
}

// Proven against: usemtl lines before mtllib resolved by name (the first face red, not -1);
// the gap check on every run whatever its material (an error for the untextured red faces);
// a triangle's material taken from the usemtl after it.
TEST_CASE("obj reader: materials=obj groups, materials and texture coordinates as before") {
    TempDir d;
    const std::string mtl = "newmtl red\nKd 0.8 0.1 0.2\nKs 0.3 0.6 0.9\nNs 50\nNi 1.5\nd 0.75\n"
                            "newmtl pic\nKd 1 1 1\nmap_Kd quad.png\nnewmtl blue\nKd 0 0 1\n";
    // Faces before any usemtl, a usemtl before the library (no material), an unknown name, a
    // material used twice (one part), a textured one (its faces need vt, the others not).
    const std::string obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 3 -1 0\nv 3 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                            "f 1 2 3\nusemtl red\nf 1 3 4\nmtllib lib.mtl\nf 2 5 6\nusemtl red\nf 1 2 3 4\n"
                            "usemtl pic\nf 2/1 5/2 6/3\nf 2/1 6/3 3/4\nusemtl nosuch\nf 4 5 6\nusemtl blue\nf 3 4 5\n"
                            "usemtl red\nf 6 5 4\n";
    d.write("lib.mtl", mtl);
    const std::string path = d.write("m.obj", obj);
    const ObjModel model = load_obj_model(path, false);
    tinyobj::ObjReaderConfig config;
    tinyobj::ObjReader lib;
    REQUIRE(lib.ParseFromString("mtllib x\n", mtl, config));
    const auto& mats = lib.GetMaterials();
    const Oracle o = oracle(obj, mtl, true, [&](int m) { return (m >= 0 && !mats[std::size_t(m)].diffuse_texname.empty()); });
    REQUIRE(model.parts.size() == o.groups.size());
    REQUIRE(model.parts.size() == 4);  // -1 (first faces, before the library, unknown name), red, pic, blue
    std::size_t k = 0;
    for (const auto& [key, g] : o.groups) {
        INFO("material ", key);
        CHECK(model.parts[k].material == key);
        check_same_mesh(*model.parts[k].mesh, *Mesh::build(path, o.positions, g.tris, {}, g.corner_uv));
        ++k;
    }
    CHECK(model.parts[0].mesh->triangle_count() == 4);  // 2 before red is read, 1 after, 1 nosuch
    REQUIRE(model.materials.size() == 3);
    CHECK(model.materials[0].name == "red");
    CHECK(model.materials[1].map_kd == "quad.png");
    CHECK(model.mtl_path == (d.dir / "lib.mtl").string());
    REQUIRE(o.materials.size() == model.materials.size());
    for (std::size_t m = 0; m < o.materials.size(); ++m) {
        CHECK(model.materials[m].name == o.materials[m].name);
        CHECK(model.materials[m].kd[2] == o.materials[m].diffuse[2]);
        CHECK(model.materials[m].d == o.materials[m].dissolve);
    }
    // Textured (with_uv): every face needs vt; the first without is at line 11, column 3.
    try {
        load_obj_model(path, true);
        FAIL("no error");
    } catch (const std::runtime_error& e) {
        CHECK(std::string(e.what()) == path + ":11:3: face without texture coordinates (vt), which a texture needs");
    }
    // A mapped material's face without vt: only that one is refused.
    const std::string bad = d.write("bad.obj", "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 2 3\nusemtl pic\nf 1/1 2/1 3/1\nf 1/1 2 3/1\n");
    try {
        load_obj_model(bad, false);
        FAIL("no error");
    } catch (const std::runtime_error& e) {
        CHECK(std::string(e.what()) == bad + ":9:7: face without texture coordinates (vt), which a texture needs");
    }
}

// Proven against: chunks cut at any byte (a line split: errors at small chunk sizes); each
// chunk's first gap kept (more gaps at chunk size 1); relative vt counted with the vertices.
TEST_CASE("obj reader: the same data at every chunk size and thread count") {
    std::string text;
    for (const auto& [name, t] : cases()) text += t + "\n";
    text += "vt 0 0\nvt 1 0\nvt 1 1\nmtllib lib.mtl\nusemtl a\nf -1/-1 -2/-2 -3/-3\nf 1 2 3\nf 1/1 2/2 3/3 4\nusemtl b\nf 3 4 5\n";
    ObjData first;
    bool have = false;
    for (const int jobs : {1, 2})
        for (const std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(64), std::size_t(4096), std::size_t(1) << 20}) {
            INFO("-j", jobs, ", chunk bytes ", chunk);
            Parallelism par(jobs);
            const ObjData d = par.run([&] { return parse_obj(text, "all.obj", {.keep_uv = true, .chunk_bytes = chunk}); });
            REQUIRE(d.triangles.size() > 3 * 1000);
            if (!have) {
                first = d;
                have = true;
                CHECK(d.triangle_uv == oracle_uv_indices(text));
                REQUIRE(d.material_uses.size() == 4);
                CHECK(d.material_uses[1].before_library);  // usemtl nothing, in "blanks"
                CHECK(!d.material_uses[2].before_library);
                CHECK(d.mtllib == "lib.mtl");
                REQUIRE(d.uv_gaps.size() == 5);  // the file's start, after each "nothing", "a" and "b"
                continue;
            }
            CHECK(d.positions == first.positions);
            CHECK(d.texcoords == first.texcoords);
            CHECK(d.normal_count == first.normal_count);
            CHECK(d.triangles == first.triangles);
            CHECK(d.triangle_uv == first.triangle_uv);
            CHECK(d.mtllib == first.mtllib);
            REQUIRE(d.material_uses.size() == first.material_uses.size());
            for (std::size_t k = 0; k < d.material_uses.size(); ++k) {
                CHECK(d.material_uses[k].first_triangle == first.material_uses[k].first_triangle);
                CHECK(d.material_uses[k].name == first.material_uses[k].name);
                CHECK(d.material_uses[k].before_library == first.material_uses[k].before_library);
            }
            REQUIRE(d.uv_gaps.size() == first.uv_gaps.size());
            for (std::size_t k = 0; k < d.uv_gaps.size(); ++k) {
                CHECK(d.uv_gaps[k].triangle == first.uv_gaps[k].triangle);
                CHECK(d.uv_gaps[k].offset == first.uv_gaps[k].offset);
            }
        }
}

// Each message proven against its check removed or weakened: the relative-index bound (a
// wrapped index, no error), the float range ("1e39" read as inf, refused as not finite), the
// underflow ("1e-50" refused), the vertex limit, a lone '\r' not counted as a line in the
// location, control bytes quoted raw.
TEST_CASE("obj reader: malformed files are refused at file:line:col") {
    const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    const struct {
        std::string text;
        std::string error;
    } kCases[] = {
        {"v 1 2\n", "m.obj:1:6: expected a vertex coordinate (v x y z) before the end of the line"},
        {"v 1 abc 3\n", "m.obj:1:5: expected a vertex coordinate (v x y z), got 'abc'"},
        {"v 1 2 3x\n", "m.obj:1:7: expected a vertex coordinate (v x y z), got '3x'"},
        {"v 1 +-2 3\n", "m.obj:1:5: expected a vertex coordinate (v x y z), got '+-2'"},
        {"v\n", "m.obj:1:2: expected a vertex coordinate (v x y z) before the end of the line"},
        {"v 1 2 3 4 5 6 7 8\n", "m.obj:1:17: unexpected '8' after a vertex's x y z and 4 more numbers (w or a colour)"},
        {"v nan 0 0\n", "m.obj:1:3: 'nan' is not a finite number"},
        {"v 0 -inf 0\n", "m.obj:1:5: '-inf' is not a finite number"},
        {"v 0 0 1e39\n", "m.obj:1:7: '1e39' is beyond the float range"},
        {"v 0 0 -1e4000\n", "m.obj:1:7: '-1e4000' is beyond the float range"},
        {"v 0 0 1\x01\n", "m.obj:1:7: expected a vertex coordinate (v x y z), got '1\\x01'"},
        {"vt\n", "m.obj:1:3: expected a texture coordinate (vt u [v [w]]) before the end of the line"},
        {"vt 0.5 inf\n", "m.obj:1:8: 'inf' is not a finite number"},
        {"vt 0 0 0 0\n", "m.obj:1:10: unexpected '0' after a texture coordinate's u v w"},
        {v3 + "f 1 2\n", "m.obj:4:1: a face needs at least 3 corners, got 2"},
        {v3 + "f\n", "m.obj:4:1: a face needs at least 3 corners, got 0"},
        {v3 + "f 1 2 0\n", "m.obj:4:7: vertex index 0 (OBJ numbers them from 1)"},
        {v3 + "f 1 2 4\n", "m.obj:4:7: vertex index 4 is out of range: the file has 3 vertices"},
        {v3 + "f 1 2 99999999999999999999\n", "m.obj:4:7: vertex index 99999999999999999999 is out of range: the file has 3 vertices"},
        {v3 + "f -1 -2 -4\n", "m.obj:4:9: relative vertex index -4 reaches before the first vertex (3 vertices so far)"},
        {"f -1 -2 -3\n" + v3, "m.obj:1:3: relative vertex index -1 reaches before the first vertex (0 vertices so far)"},
        {v3 + "vt 0 0\nf 1/1 2/2 3/1\n", "m.obj:5:9: texture coordinate index 2 is out of range: the file has 1 texture coordinate"},
        {v3 + "f 1//1 2//1 3//1\n", "m.obj:4:6: normal index 1 is out of range: the file has 0 normals"},
        {v3 + "vn 0 0 1\nf 1//1 2//-2 3//1\n", "m.obj:5:11: relative normal index -2 reaches before the first normal (1 normal so far)"},
        {v3 + "f 1/ 2 3\n", "m.obj:4:5: expected a texture coordinate index, got a blank"},
        {v3 + "vt 0 0\nf 1/1/ 2 3\n", "m.obj:5:7: expected a normal index, got a blank"},
        {v3 + "vt 0 0\nvn 0 0 1\nf 1/1/1/1 2 3\n", "m.obj:6:8: unexpected '/1' in a face corner (v, v/vt, v//vn or v/vt/vn)"},
        {v3 + "f 1.5 2 3\n", "m.obj:4:4: unexpected '.5' in a face corner (v, v/vt, v//vn or v/vt/vn)"},
        {v3 + "f a b c\n", "m.obj:4:3: expected a vertex index, got 'a'"},
        {v3 + "f 1 2 \\\n3\n", "m.obj:4:7: expected a vertex index, got '\\' (lines are not continued: one statement a line)"},
        {"v 0 0 0\r\nv 1 0 0\r\n\r\nv 0 x 0\r\n", "m.obj:4:5: expected a vertex coordinate (v x y z), got 'x'"},
        {"v 0 0 0\rv 1 0 0\r\rv 0 x 0\r", "m.obj:4:5: expected a vertex coordinate (v x y z), got 'x'"},
        {"#" + std::string(100000, 'c') + "\n" + v3 + "f 1 2 3 5", "m.obj:5:9: vertex index 5 is out of range: the file has 3 vertices"},
    };
    for (const auto& c : kCases) {
        INFO("text: ", c.text.substr(0, 200));
        for (const std::size_t chunk : {std::size_t(1) << 20, std::size_t(5)}) CHECK(parse_error(c.text, {.chunk_bytes = chunk}) == c.error);
    }
    // A number too small for a float is 0, as tinyobjloader read it.
    const ObjData tiny = parse_obj("v 1e-50 -1e-4000 0.5\n", "m.obj");
    REQUIRE(tiny.positions.size() == 3);
    CHECK(tiny.positions[0] == 0.f);
    CHECK(tiny.positions[1] == 0.f);
    CHECK(std::signbit(tiny.positions[1]));
    CHECK(tiny.positions[2] == 0.5f);
    // Absurd counts: more vertices than allowed, at the first one too many.
    CHECK(parse_error(v3 + v3, {.max_vertices = 4}) == "m.obj:5:1: more than 4 vertices");
    CHECK(parse_error("  v 1 2 3\n  v 1 2 3\n", {.chunk_bytes = 1, .max_vertices = 1}) == "m.obj:2:3: more than 1 vertex");
}

// Proven against: the chunks' errors taken from the last chunk first.
TEST_CASE("obj reader: the first error in the file, whatever the chunks and threads") {
    std::string text;
    for (int i = 0; i < 5000; ++i) text += "v " + std::to_string(i) + " 0 0\n";
    text += "v 1 2 oops\n";
    for (int i = 0; i < 5000; ++i) text += "f 1 2 3\n";
    text += "f 1 2 0\nv nan 0 0\n";
    const std::string expected = "m.obj:5001:7: expected a vertex coordinate (v x y z), got 'oops'";
    for (const int jobs : {1, 2})
        for (const std::size_t chunk : {std::size_t(3), std::size_t(100), std::size_t(1) << 20}) {
            Parallelism par(jobs);
            CHECK(par.run([&] { return parse_error(text, {.chunk_bytes = chunk}); }) == expected);
        }
}

// Proven against: load_obj_mesh reporting a missing vt at the file's start (line 1, column 1).
TEST_CASE("obj reader: through load_obj_mesh and the scene, with the file's location") {
    TempDir d;
    const std::string path = d.write("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 3/1 2 1/1\n");
    CHECK(load_obj_mesh(path)->triangle_count() == 2);
    try {
        load_obj_mesh(path, true);
        FAIL("no error");
    } catch (const std::runtime_error& e) {
        CHECK(std::string(e.what()) == path + ":6:7: face without texture coordinates (vt), which a texture needs");
    }
    const std::string bad = d.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 7\n");
    try {
        parse_scene("sphere\nmesh file=bad.obj\n", (d.dir / "s.cfg").string());
        FAIL("no error");
    } catch (const SceneError& e) {
        CHECK(std::string(e.what()) == (d.dir / "s.cfg").string() + ":2:11: '" + bad + "': " + bad +
                                           ":4:9: vertex index 7 is out of range: the file has 3 vertices");
    }
    try {
        load_obj_mesh((d.dir / "none.obj").string());
        FAIL("no error");
    } catch (const std::runtime_error& e) {
        CHECK(std::string(e.what()) == "cannot open mesh file");
    }
}

TEST_CASE("obj reader: vertex colours (v x y z r g b [a]) kept on request, the first vertex without one found") {
    // Vertex 3 has a w only, vertex 5 nothing after x y z: the first of them is line 4.
    const std::string text = "# colours\nv 0 0 0 1 0.5 0.25\nv 1 0 0 0.125 0 1 0.5\nv 0 1 0 2\nv 1 1 0 0 0 0\nv 2 2 0\n"
                             "f 1 2 3\nf 2 4 3\n";
    const std::size_t line4 = text.find("v 0 1 0 2");
    for (const int jobs : {1, 2})
        for (const std::size_t chunk : {std::size_t(1), std::size_t(9), std::size_t(40), std::size_t(1) << 20}) {
            INFO("-j", jobs, ", chunk bytes ", chunk);
            Parallelism par(jobs);
            const ObjData d = par.run([&] { return parse_obj(text, "c.obj", {.keep_colors = true, .chunk_bytes = chunk}); });
            CHECK(d.colors == std::vector<float>{1, 0.5f, 0.25f, 0.125f, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0});
            CHECK(d.colorless_offset == line4);
            CHECK(d.positions.size() == 15);
            const ObjData plain = par.run([&] { return parse_obj(text, "c.obj", {.chunk_bytes = chunk}); });
            CHECK(plain.colors.empty());  // not asked for: nothing kept
            CHECK(plain.colorless_offset == std::size_t(-1));
        }
    const ObjData all = parse_obj("v 0 0 0 1 1 1\nv 1 0 0 0 0 0\nv 0 1 0 0.5 0.5 0.5\nf 1 2 3\n", "c.obj", {.keep_colors = true});
    CHECK(all.colorless_offset == std::size_t(-1));
    CHECK(all.colors.size() == 9);
}
