// Every input the fuzzer (tests/fuzz/scene_fuzz.cpp, scripts/fuzz.sh) found crashing or
// breaking the parser's contract, kept in tests/fuzz/regressions/, replayed exactly as the
// fuzzer ran it; plus the same bugs written out as readable inline cases.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/include_tree.h"
#include "fuzz/scene_contract.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

struct FuzzDir {
    fs::path dir;
    FuzzDir() {
        dir = fs::temp_directory_path() / ("streamrt_fuzz_regressions_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        streamrt_fuzz::make_include_tree(dir);
    }
    ~FuzzDir() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

/// "" when `text` either parses into a valid scene or fails with a well-formed SceneError.
std::string run_input(const std::string& text, const fs::path& dir) {
    try {
        return streamrt_fuzz::check_scene(parse_scene(text, (dir / "input.cfg").string()));
    } catch (const SceneError& e) {
        return streamrt_fuzz::check_error(e);
    }
}

std::string error_of(const std::string& text) {
    try {
        parse_scene(text, "t.cfg");
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST_CASE("fuzz regressions: every saved input keeps the parser's contract") {
    const fs::path folder = fs::path(STREAMRT_SOURCE_DIR) / "tests" / "fuzz" / "regressions";
    REQUIRE(fs::is_directory(folder));
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(folder))
        if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    REQUIRE(!files.empty());
    FuzzDir tmp;
    for (const fs::path& f : files) {
        std::ifstream in(f, std::ios::binary);
        std::ostringstream ss;
        ss << in.rdbuf();
        INFO("input: ", f.filename().string());
        CHECK(run_input(ss.str(), tmp.dir) == "");
    }
}

TEST_CASE("fuzz regressions: control bytes in a message are escaped, the message stays one line") {
    const std::string e = error_of("sphere colo\x01r=1,1,1\n");
    CHECK(e.find("t.cfg:1:8: unknown key 'colo\\x01r'") == 0);
    CHECK(std::none_of(e.begin(), e.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; }));
    const std::string esc = error_of("image width=1\x1b[2J\n");
    CHECK(esc.find("'1\\x1b[2J'") != std::string::npos);
    const std::string nul = error_of(std::string("cube\0x", 6) + "\n");
    CHECK(nul.find("\\x00") != std::string::npos);
}

TEST_CASE("fuzz regressions: a finite Md whose inverse overflows is rejected as singular") {
    // scale 1e-10 then translate 1e308: Md is finite but Mi's translation is -1e318 = inf.
    const std::string e = error_of("sphere scale=1e-10 translate=1e308,0,0\n");
    CHECK(e.find("t.cfg:1:1: sphere: the composed transform is singular") == 0);
    const std::string cam = error_of("camera rx=1e-10 ry=1e-10 df=1e-10 translate=1e308,1e308,1e308\n");
    CHECK(cam.find("t.cfg:1:1: camera: the composed transform is singular") == 0);
    // Neighbours that are fine stay accepted.
    CHECK(error_of("sphere scale=1e-10 translate=1e290,0,0\n") == "");
    CHECK(error_of("sphere scale=1e50 translate=1e100,0,0\n") == "");
    // The inverse is computed as glm::inverse does (cofactors): scale 1e100 with translate
    // 1e300 overflows there (1e400) although the exact inverse is finite; rejected too.
    CHECK(error_of("sphere scale=1e100 translate=1e300,0,0\n").find("singular") != std::string::npos);
}

TEST_CASE("fuzz regressions: a huge rotation angle is reduced without overflowing a long") {
    // -5.5e31 degrees is an exact multiple of 90 whose quarter turns do not fit in a long
    // (undefined behaviour before); now taken modulo a full turn.
    const Scene sc = parse_scene("cone rotate_x=-55555555555555555555555555555555\n", "t.cfg");
    REQUIRE(sc.objects.size() == 1);
    CHECK(streamrt_fuzz::check_scene(sc) == "");
    const Scene big = parse_scene("cube rotate_y=1e300 rotate_z=-1e308\n", "t.cfg");
    CHECK(streamrt_fuzz::check_scene(big) == "");
}

TEST_CASE("fuzz regressions: an include path with a NUL byte is refused, not truncated") {
    // "bad.cfg\0(g" used to open bad.cfg (the OS stops at the NUL) and report its errors
    // under a file name containing a NUL.
    FuzzDir tmp;
    const std::string input = tmp.dir.string() + "/input.cfg";
    try {
        parse_scene(std::string("include bad.cfg\0(g\n", 19), input);
        FAIL("expected a SceneError");
    } catch (const SceneError& e) {
        CHECK(std::string(e.what()) == input + ":1:9: include path 'bad.cfg\\x00(g' contains a control byte");
    }
}
