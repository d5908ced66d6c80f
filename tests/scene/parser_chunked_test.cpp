// The chunked, parallel reader (ReadOptions): the same Scene as the one-pass reader, and the
// same first error, wherever the chunk boundaries fall.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>
#include <string>

#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

/// One pass, one thread: the reference.
ReadOptions one_pass() {
    ReadOptions o;
    o.jobs = 1;
    o.chunked_from = SIZE_MAX;
    return o;
}

/// Chunked whatever the size, small chunks so that a few MB make hundreds of them.
ReadOptions chunked(int jobs, std::size_t chunk = 16 << 10) {
    ReadOptions o;
    o.jobs = jobs;
    o.chunk_bytes = chunk;
    o.chunked_from = 0;
    return o;
}

/// A scene of `n` shape lines using every statement kind, comments, blank lines, tabs, CRLF,
/// materials defined all along the file (each used only after its definition).
std::string big_scene(int n) {
    std::string s = "\xEF\xBB\xBF# generated\nimage width=320 height=200 spp=2 depth=3 degree=4 output=a.png\n";
    s += "ambient 0.2\nbackground 0.1,0.2,0.3\ncamera eye=0,5,20 look=0,0,0 up=0,1,0 fov=50\n";
    s += "light point pos=1,10,2 color=0.5,0.5,0.5\nmaterial m0 color=0.5,0.5,0.5 spec=0.3\n";
    const char* kinds[] = {"sphere", "cube", "cylinder", "cone", "torus", "plane"};
    char line[256];
    for (int i = 0; i < n; ++i) {
        if (i % 5000 == 4999) {
            std::snprintf(line, sizeof line, "material m%d material=m%d refl=0.%d\n", i, i >= 5000 ? i - 5000 : 0,
                          i % 9);
            s += line;
            s += "light spot pos=0,9,0 dir=0,-1,0 angle=20\ncamera rx=1.5 ry=1 df=2 rotate_x=-10 translate=0,1,6\n";
        }
        if (i % 997 == 0) s += "\n   # a comment line\n";
        const int m = (i / 5000) * 5000 - 1;
        std::snprintf(line, sizeof line,
                      "%s%s color=0.%d,0.%d,0.5 diff=0.85 %s scale=%d.25,1.5,0.75 rotate_y=%d translate=%d,0.5,-%d.125%s",
                      i % 7 == 0 ? "\t " : "", kinds[i % 6], i % 10, (i / 10) % 10,
                      m < 0 ? "material=m0" : ("material=m" + std::to_string(m)).c_str(), 1 + i % 3, i % 360, i,
                      i % 100, i % 11 == 0 ? " minor=0.3 # torus only\r\n" : "\n");
        // minor is only for tori: keep it there.
        std::string l = line;
        if (i % 6 != 4) {
            const auto p = l.find(" minor=0.3");
            if (p != std::string::npos) l.erase(p, 10);
        }
        s += l;
    }
    s += "ambient 0.3";  // no final newline
    return s;
}

/// Every field of both scenes, exactly (a mesh: present in both; each read loads its own).
void same_scene(const Scene& a, const Scene& b) {
    CHECK(a.path == b.path);
    const RenderSettings &sa = a.settings, &sb = b.settings;
    CHECK(sa.width == sb.width);
    CHECK(sa.height == sb.height);
    CHECK(sa.spp == sb.spp);
    CHECK(sa.depth == sb.depth);
    CHECK(sa.degree == sb.degree);
    CHECK(sa.ambient == sb.ambient);
    CHECK(sa.background == sb.background);
    CHECK(sa.calibration == sb.calibration);
    CHECK(sa.pattern == sb.pattern);
    CHECK(sa.output == sb.output);
    CHECK(a.camera.look_at == b.camera.look_at);
    CHECK(a.camera.md == b.camera.md);
    CHECK(a.camera.eye == b.camera.eye);
    CHECK(a.camera.look == b.camera.look);
    CHECK(a.camera.up == b.camera.up);
    CHECK(a.camera.fov == b.camera.fov);
    REQUIRE(a.lights.size() == b.lights.size());
    for (std::size_t i = 0; i < a.lights.size(); ++i) {
        CHECK(a.lights[i].kind == b.lights[i].kind);
        CHECK(a.lights[i].pos == b.lights[i].pos);
        CHECK(a.lights[i].dir == b.lights[i].dir);
        CHECK(a.lights[i].color == b.lights[i].color);
        CHECK(a.lights[i].angle == b.lights[i].angle);
    }
    // The deduplicated materials, in the same order (first use in file order).
    REQUIRE(a.materials.size() == b.materials.size());
    for (std::size_t i = 0; i < a.materials.size(); ++i) CHECK(a.materials[i] == b.materials[i]);  // every registered property
    CHECK(a.meshes.size() == b.meshes.size());
    REQUIRE(a.objects.size() == b.objects.size());
    int differing = 0;  // one message for the first difference, not millions
    for (std::size_t i = 0; i < a.objects.size() && differing == 0; ++i) {
        const Object &x = a.objects[i], &y = b.objects[i];
        const SourceLoc wx = a.where(i), wy = b.where(i);
        const bool same = x.kind == y.kind && x.param == y.param && x.mesh == y.mesh && x.md == y.md &&
                          x.color == y.color && x.material == y.material && wx.file == wy.file &&
                          wx.line == wy.line && wx.column == wy.column;
        if (!same) {
            INFO("object ", i, " (line ", wx.line, " vs ", wy.line, ")");
            CHECK(same);
            ++differing;
        }
    }
}

/// The SceneError `f` throws, or a failed check.
template <class F>
SceneError error_of(F&& f) {
    try {
        f();
    } catch (const SceneError& e) {
        return e;
    }
    FAIL("expected a SceneError");
    return SceneError(SourceLoc{}, "");
}

void same_error(const SceneError& a, const SceneError& b) {
    CHECK(std::string(a.what()) == std::string(b.what()));
    CHECK(a.where().line == b.where().line);
    CHECK(a.where().column == b.where().column);
}

/// Chunked at -j2, `text` fails at line:column with `message`, exactly as one pass does.
void expect_error(const std::string& text, int line, int column, const std::string& message) {
    const SceneError e = error_of([&] { parse_scene(text, "big.cfg", chunked(2)); });
    CHECK(e.where().file == "big.cfg");
    CHECK(e.where().line == line);
    CHECK(e.where().column == column);
    CHECK(e.message() == message);
    same_error(e, error_of([&] { parse_scene(text, "big.cfg", one_pass()); }));
}

/// `text` with line `line` (1-based) replaced.
std::string with_line(const std::string& text, int line, const std::string& replacement) {
    std::size_t b = 0;
    for (int l = 1; l < line; ++l) b = text.find('\n', b) + 1;
    const std::size_t e = text.find('\n', b);
    return text.substr(0, b) + replacement + text.substr(e);
}

}  // namespace

TEST_CASE("parser: chunked reader: the same scene as one pass, every field, at -j1 and -j2") {
    const std::string text = big_scene(40000);  // ~4.5 MB, ~280 chunks of 16 KiB
    REQUIRE(text.size() > (4u << 20));
    const Scene ref = parse_scene(text, "big.cfg", one_pass());
    REQUIRE(ref.objects.size() == 40000);
    CHECK(ref.where(ref.objects.size() - 1).line > 40000);
    CHECK(ref.lights.size() == 1 + 40000 / 5000);
    CHECK(ref.settings.ambient == 0.3);
    CHECK_FALSE(ref.camera.look_at);
    for (const int jobs : {1, 2}) {
        INFO("jobs ", jobs);
        same_scene(parse_scene(text, "big.cfg", chunked(jobs)), ref);
    }
    // Chunks of one byte: every line its own chunk.
    same_scene(parse_scene(text.substr(0, 20000), "big.cfg", chunked(2, 1)),
               parse_scene(text.substr(0, 20000), "big.cfg", one_pass()));
}

TEST_CASE("parser: chunked reader: load_scene (mapped, pages given back) reads the file as parse_scene does") {
    const fs::path p = fs::temp_directory_path() / ("streamrt_chunked_" + std::to_string(::getpid()) + ".cfg");
    const std::string text = big_scene(20000);
    std::ofstream(p, std::ios::binary) << text;
    ReadOptions o = chunked(2);
    const Scene mapped = load_scene(p.string(), o);
    fs::remove(p);
    same_scene(mapped, parse_scene(text, p.string(), one_pass()));
}

TEST_CASE("parser: chunked reader: the first error in file order wins over errors in later chunks") {
    const std::string text = big_scene(40000);
    // A shape error in an early chunk, then errors of every kind in later chunks.
    std::string bad = with_line(text, 30000, "sphere scale=0");                   // shape
    bad = with_line(bad, 31000, "bogus statement");                               // other statement
    bad = with_line(bad, 32000, "material m0 color=1,1,1");                       // redefinition
    bad = with_line(bad, 2000, "cube color=1,2 translate=0,0,0");                 // the first
    expect_error(bad, 2000, 12, "expected 3 comma-separated numbers x,y,z for 'color', got '1,2'");

    // The first error is a non-shape statement; shapes after it are broken too.
    std::string other = with_line(text, 35000, "cone translate=a,b,c");
    other = with_line(other, 3000, "light point color=1,1,1");
    expect_error(other, 3000, 1, "light point needs 'pos=x,y,z'");

    // A shape error before a broken non-shape statement of a later chunk.
    std::string shape_first = with_line(text, 36000, "ambient 2");
    shape_first = with_line(shape_first, 4000, "torus minor=-1");
    expect_error(shape_first, 4000, 13, "'minor' must be > 0, got '-1'");
}

TEST_CASE("parser: chunked reader: an error in a late chunk has its line and column") {
    const std::string text = big_scene(40000);
    const int last = int(std::count(text.begin(), text.end(), '\n')) + 1;
    const std::string bad = with_line(text, last - 3, "  sphere diff=0.5 translate=1,2,3x");
    expect_error(bad, last - 3, 29, "expected 3 comma-separated numbers x,y,z for 'translate', got '1,2,3x'");
}

TEST_CASE("parser: chunked reader: a material defined in a later chunk than its use is refused") {
    std::string text = big_scene(40000);
    text = with_line(text, 20, "sphere material=late  translate=1,1,1");
    text = with_line(text, 38000, "material late color=1,0,0");
    expect_error(text, 20, 17, "unknown material 'late' (a material must be defined before it is used)");
    // Used after its definition, in a later chunk, it is found.
    const Scene ok = parse_scene(with_line(with_line(text, 20, "# was here"), 39000, "cube material=late"), "big.cfg",
                                 chunked(2));
    bool found = false;
    for (std::size_t i = 0; i < ok.objects.size(); ++i)
        if (ok.where(i).line == 39000)
            found = ok.objects[i].kind == ShapeKind::Cube && ok.objects[i].color == glm::vec3(1, 0, 0);
    CHECK(found);
}

namespace {

/// The scene, or the error's full text, read with `options`.
std::string outcome(const std::string& text, const std::string& name, const ReadOptions& options, Scene& out) {
    try {
        out = parse_scene(text, name, options);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

void same_outcome(const std::string& text, const std::string& name) {
    INFO("input: ", name);
    Scene a, b;
    const std::string ea = outcome(text, name, one_pass(), a);
    for (const std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(64)}) {
        const std::string eb = outcome(text, name, chunked(2, chunk), b);
        CHECK(ea == eb);
        if (ea.empty() && eb.empty()) same_scene(b, a);
    }
}

}  // namespace

TEST_CASE("parser: chunked reader: odd texts, the fuzz regressions and every scene read as in one pass") {
    const std::string odd[] = {
        "",
        "\n\n\n",
        "\xEF\xBB\xBF\xEF\xBB\xBFsphere\n",         // only the first BOM is skipped
        "sphere\rcube\r\n",                         // a lone CR is a space
        std::string("cube\0x\nsphere\n", 14),       // NUL byte
        "#\n#\nsphere color=1,1,1#x\ncube",         // comments, no final newline
        "cube#glued\n  sphere#\n",                 // a comment glued to the word
        "sphere material=m\nmaterial m\n",          // used before its definition
        "material m\nmaterial m\nsphere material=m\n",  // redefined
        "material m color=1,0,0\nsphere material=m\nmaterial n material=m diff=0.5\ncone material=n\n",
        "sphere scale=0\nbogus\n",
        "bogus\nsphere scale=0\n",
        "camera eye=0,0,1 look=0,0,1\nsphere translate=x\n",
        "light spot pos=0,1,0\nimage width=0\n",
        "torus minor=0.1 minor=0.2\n",
    };
    for (const std::string& t : odd) same_outcome(t, "t.cfg");

    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(fs::path(STREAMRT_SOURCE_DIR) / "tests" / "fuzz" / "regressions"))
        if (e.is_regular_file()) files.push_back(e.path());
    for (const auto& e : fs::recursive_directory_iterator(fs::path(STREAMRT_SOURCE_DIR) / "scenes"))
        if (e.is_regular_file() && e.path().extension() == ".cfg") files.push_back(e.path());
    REQUIRE(files.size() > 10);
    for (const fs::path& f : files) {
        std::ifstream in(f, std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        same_outcome(text, f.string());
    }
}
