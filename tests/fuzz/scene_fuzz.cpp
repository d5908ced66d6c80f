// libFuzzer target for the whole load-validate path: parse_scene() on arbitrary bytes (with
// `include` resolved inside a private temporary folder holding a few small scene files),
// then the checks the command line makes before rendering (camera placement for the chosen
// image size, the memory estimate). Built and run by scripts/fuzz.sh.
//
// Besides "no crash, no sanitizer report", it asserts the parser's contract:
//  - the only exception is SceneError, whose text is "FILE:LINE:COL: message" on one line
//    with no control characters;
//  - a scene that parses is fully valid: settings in their documented ranges, every
//    transform finite and invertible with finite Mi and Mn, light directions unit length.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "render/limits.h"
#include "scene/parser.h"

namespace {

namespace fs = std::filesystem;
using namespace streamrt;

std::string g_name;  // the fuzz input's file name, inside the temporary folder

[[noreturn]] void fail(const char* what, const std::string& detail) {
    std::fprintf(stderr, "scene_fuzz: contract broken: %s: %s\n", what, detail.c_str());
    std::abort();
}

void write(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

// Files an input may include by name: a valid fragment, a chain, a self-cycle, a mutual
// cycle, a file with an error, a folder (not a file) and an empty file.
void make_include_tree(const fs::path& dir) {
    fs::create_directories(dir / "sub");
    write(dir / "a.cfg", "material m color=1,0,0 refl=0.5 trans=0.5 ior=1.5\nlight point pos=0,5,0\n");
    write(dir / "b.cfg", "include a.cfg\nimage width=8 height=8\n");
    write(dir / "self.cfg", "include self.cfg\n");
    write(dir / "c1.cfg", "include c2.cfg\n");
    write(dir / "c2.cfg", "include c1.cfg\n");
    write(dir / "bad.cfg", "sphere scale=0\n");
    write(dir / "empty.cfg", "");
    write(dir / "sub" / "up.cfg", "include ../a.cfg\ncamera eye=0,0,5 look=0,0,0\n");
    write(dir / "twice.cfg", "include empty.cfg\ninclude empty.cfg\ninclude twice.cfg\n");
}

bool finite(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}
bool finite(const glm::dmat3& m) {
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}
bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void check_error(const SceneError& e) {
    const std::string what = e.what();
    for (unsigned char c : what)
        if (c < 0x20 || c == 0x7f) fail("message has a control character", what);
    const SourceLoc& at = e.where();
    if (at.line < 1 || at.column < 1) fail("error without line:col", what);
    if (what.rfind(at.str() + ": ", 0) != 0) fail("message does not start with file:line:col:", what);
    if (e.message().empty()) fail("empty message", what);
}

void check_scene(const Scene& sc) {
    const RenderSettings& s = sc.settings;
    if (s.width < 1 || s.width > 32768 || s.height < 1 || s.height > 32768) fail("size", std::to_string(s.width));
    if (s.spp < 1 || s.spp > 65536 || s.depth < 0 || s.depth > 256 || s.degree < 0 || s.degree > 5)
        fail("settings out of range", std::to_string(s.spp));
    if (!(s.ambient >= 0 && s.ambient <= 1) || !finite(s.background) || s.output.empty())
        fail("ambient/background/output", s.output);
    for (const Object& o : sc.objects) {
        if (!finite(o.xf.md) || !finite(o.xf.mi) || !finite(o.xf.mn)) fail("object transform not finite", o.where.str());
        if (!(o.minor > 0) || !std::isfinite(o.minor)) fail("torus minor", o.where.str());
        const Material& m = o.material;
        if (!finite(m.color) || !(m.ior > 0) || !(m.cell > 0) || !std::isfinite(m.cell))
            fail("material", o.where.str());
    }
    for (const Light& l : sc.lights) {
        if (!finite(l.pos) || !finite(l.color)) fail("light not finite", "");
        if (std::fabs(glm::length(l.dir) - 1.0) > 1e-9) fail("light direction not unit", "");
    }
    const glm::dmat4 cam = sc.camera.world_from_canonical(s.width, s.height);
    if (!finite(cam) || !finite(glm::inverse(cam))) fail("camera transform not finite or not invertible", "");
    // The command line's memory check must never overflow or throw anything but UsageError.
    for (int stream = 0; stream < 2; ++stream) {
        const MemoryEstimate est = estimate_render_memory(sc, stream == 1, 2);
        if (!(est.total_bytes >= est.framebuffer_bytes)) fail("memory estimate", "");
        try {
            check_render_memory(sc, stream == 1, 2);
        } catch (const UsageError& e) {
            const std::string what = e.what();
            if (what.find('\n') != std::string::npos) fail("multi-line usage error", what);
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    char tmpl[] = "/tmp/streamrt_fuzz_XXXXXX";
    if (!::mkdtemp(tmpl)) std::abort();
    static const fs::path dir(tmpl);
    make_include_tree(dir);
    std::atexit([] {
        std::error_code ec;
        fs::remove_all(dir, ec);
    });
    g_name = (dir / "input.cfg").string();
    // Relative includes resolve against the input's folder (the working directory is left
    // alone: libFuzzer writes its artifacts relative to it).
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const Scene sc = parse_scene(text, g_name);
        check_scene(sc);
    } catch (const SceneError& e) {
        check_error(e);
    }
    return 0;
}
