// The streamrt command end to end (the binary is STREAMRT_BINARY): exit codes, one-line
// errors, --check, output-path checks before rendering, limits, and Ctrl-C.
#include <doctest/doctest.h>

#include "cli/cli_support.h"
#include "image/image_io.h"
#include "driver/render.h"
#include "scene/parser.h"
#include <signal.h>
#include <stb_image.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace cli_support;

namespace {

/// The PFM the command wrote equals, float for float, the stream engine's render of the
/// scene in this process (which keeps every table of the scene alive).
void check_same_as_in_process_stream(const fs::path& scene, const fs::path& out) {
    streamrt::Parallelism par(2);
    const streamrt::Framebuffer in_process =
        streamrt::render_scene(streamrt::load_scene(scene.string()), streamrt::EngineKind::Stream, par).image;
    const streamrt::Framebuffer written = streamrt::read_image(out.string());
    REQUIRE(written.rgb.size() == in_process.rgb.size());
    CHECK(std::equal(written.rgb.begin(), written.rgb.end(), in_process.rgb.begin()));
}

const char* kSmallScene =
    "image width=32 height=24 spp=1 depth=2 degree=5 output=out.png\n"
    "camera eye=0,1,6 look=0,0,0\n"
    "light point pos=5,8,5\n"
    "sphere color=1,0,0\n";

}  // namespace

TEST_CASE("cli: --check validates a scene without rendering") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    const Run ok = run_streamrt("--check " + q(scene) + " -o " + q(d.path / "x.png"));
    CHECK(ok.code == 0);
    CHECK(ok.out.find("ok (1 objects, 1 lights, 32x24") != std::string::npos);
    CHECK(!fs::exists(d.path / "x.png"));
    CHECK(d.files().size() == 1);  // no probe file left behind

    const fs::path bad = d.write("bad.cfg", "image width=32\nsphere radius=2\n");
    const Run r = run_streamrt("--check " + q(bad));
    CHECK(r.code == 2);
    check_one_line_error(r, bad.string() + ":2:8: unknown key 'radius' for 'sphere' (expected one of:");

    const Run missing = run_streamrt("--check " + q(d.path / "nope.cfg"));
    CHECK(missing.code == 2);
    check_one_line_error(missing, "nope.cfg: cannot open scene file");

    for (const auto& name : {"whitted.cfg", "shapes.cfg", "cornell.cfg", "random_spheres.cfg", "dof.cfg", "fresnel.cfg"}) {
        const Run s = run_streamrt("--check -q " + q(fs::path(STREAMRT_SOURCE_DIR) / "scenes" / name) + " -o " +
                               q(d.path / "o.png"));
        INFO(name, ": ", s.err);
        CHECK(s.code == 0);
    }
}

TEST_CASE("cli: bad command lines are one-line errors with exit status 2") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"--width 1000000000", "--width"}, {"--width 1e9", "--width"},   {"--height 0", "--height"},
        {"--depth 1000000", "--depth"},    {"--spp 100000000", "--spp"}, {"--degree 7", "--degree"},
        {"--engine gpu", "--engine"},      {"-j 0", "--jobs"},           {"--no-such-option", "no-such-option"},
    };
    for (const auto& [args, needle] : cases) {
        const Run r = run_streamrt("--check " + q(scene) + " " + args);
        INFO(args);
        CHECK(r.code == 2);
        check_one_line_error(r, needle);
    }
    const Run none = run_streamrt("");
    CHECK(none.code == 2);
    check_one_line_error(none, "scene is required");
}

TEST_CASE("cli: absurd scene values are refused with their location") {
    Dir d;
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"image width=1e9\n", ":1:13: 'width' must be in [1, 32768], got '1e9'"},
        {"image depth=1000000\n", ":1:13: 'depth' must be in [0, 256]"},
        {"image spp=1e8\n", ":1:11: 'spp' must be in [1, 65536]"},
        {"image height=32769\n", ":1:14: 'height' must be in [1, 32768]"},
    };
    for (const auto& [text, needle] : cases) {
        const fs::path scene = d.write("s.cfg", text);
        const Run r = run_streamrt("--check " + q(scene));
        INFO(text);
        CHECK(r.code == 2);
        check_one_line_error(r, scene.string() + needle);
    }
}

TEST_CASE("cli: a render that cannot fit in memory is refused before it starts") {
    Dir d;
    // Glass that both reflects and transmits at depth 256: the stream engine traces it in
    // bounded memory (slices of max(16384, spp) rays, about 1.6 GiB a thread at spp 65536),
    // which 64 threads cannot have on any machine this runs on.
    const fs::path scene = d.write("deep.cfg",
                                   "image width=64 height=64 depth=256 degree=5 spp=65536\n"
                                   "material glass refl=0.5 trans=0.5 ior=1.5\nsphere material=glass\n");
    const Run r = run_streamrt(q(scene) + " -j 64 -o " + q(d.path / "deep.png"));
    CHECK(r.code == 1);  // a shortage of memory, not a mistake in the scene
    check_one_line_error(r, "would need about");
    CHECK(r.err.find("64 threads x") != std::string::npos);
    CHECK(r.err.find("but the memory budget of ") != std::string::npos);
    CHECK(r.err.find("(the available memory less a margin)") != std::string::npos);
    // With --memory-limit the budget is the limit less what the process holds.
    const Run limited = run_streamrt(q(scene) + " -j 2 --spp 4 --memory-limit 1M -o " + q(d.path / "deep.png"));
    CHECK(limited.code == 1);
    check_one_line_error(limited, "(--memory-limit 1.0 MiB less what the process held before)");
    CHECK(!fs::exists(d.path / "deep.png"));
    CHECK(!fs::exists(d.path / "deep.png"));
    // The same scene is fine for the recursive engine (its memory is its stack)...
    const Run rec = run_streamrt("--check --engine recursive -j 64 " + q(scene) + " -o " + q(d.path / "deep.png"));
    CHECK(rec.code == 0);
    // ...and for the stream engine at depth 256 with fewer samples (once refused: 2^256 rays).
    const Run deep = run_streamrt("--check --spp 4 -j 2 " + q(scene) + " -o " + q(d.path / "deep.png"));
    CHECK(deep.code == 0);
}

TEST_CASE("cli: output path mistakes are caught before rendering, nothing is created") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    SUBCASE("missing folder") {
        const fs::path out = d.path / "no" / "such" / "x.png";
        const Run r = run_streamrt(q(scene) + " -o " + q(out));
        CHECK(r.code == 2);
        check_one_line_error(r, "output folder '" + (d.path / "no" / "such").string() + "' does not exist");
        CHECK(!fs::exists(d.path / "no"));
        // The line names what named the file: the option, or the scene's output= at its
        // file:line:col (the value's column: "image width=8 height=6 output=" is 30 characters).
        CHECK(r.err == "streamrt: -o " + out.string() + ": output folder '" + (d.path / "no" / "such").string() +
                           "' does not exist\n");
        const fs::path own = d.write("own.cfg", "image width=8 height=6 output=" + out.string() + "\nsphere\n");
        const Run by_scene = run_streamrt(q(own));
        CHECK(by_scene.code == 2);
        CHECK(by_scene.err == "streamrt: " + own.string() + ":1:31: output=" + out.string() + ": output folder '" +
                                  (d.path / "no" / "such").string() + "' does not exist\n");
        const Run by_profile = run_streamrt(q(scene) + " -o " + q(d.path / "x.png") + " --profile=json " +
                                            q(d.path / "no" / "p.json"));
        CHECK(by_profile.code == 2);
        CHECK(by_profile.err == "streamrt: --profile=json " + (d.path / "no" / "p.json").string() + ": output folder '" +
                                    (d.path / "no").string() + "' does not exist\n");
        CHECK(!fs::exists(d.path / "no"));
        CHECK(!fs::exists(d.path / "x.png"));
    }
    SUBCASE("read-only folder") {
        // root may write anywhere permissions say otherwise; /proc refuses new files even to root.
        fs::path ro = "/proc";
        if (::geteuid() != 0) {
            ro = d.path / "ro";
            fs::create_directories(ro);
            fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
        }
        const Run r = run_streamrt(q(scene) + " -o " + q(ro / "x.png"));
        CHECK(r.code == 2);
        check_one_line_error(r, "output folder '" + ro.string() + "' is not writable");
        CHECK(!fs::exists(ro / "x.png"));
    }
    SUBCASE("the scene file itself") {
        const fs::path same = d.write("same.ppm", kSmallScene);
        const Run r = run_streamrt(q(same) + " -o " + q(same));
        CHECK(r.code == 2);
        check_one_line_error(r, "-o " + same.string() + ": is an input of the scene (the scene file)");
        CHECK(slurp(same) == kSmallScene);
    }
    SUBCASE("a folder") {
        fs::create_directories(d.path / "dir.png");
        const Run r = run_streamrt(q(scene) + " -o " + q(d.path / "dir.png"));
        CHECK(r.code == 2);
        check_one_line_error(r, "is a folder");
    }
    SUBCASE("unknown format") {
        const Run r = run_streamrt(q(scene) + " -o " + q(d.path / "x.jpg"));
        CHECK(r.code == 2);
        check_one_line_error(r, "unknown image format");
        CHECK(!fs::exists(d.path / "x.jpg"));
    }
}

namespace {

// Flat colours (degree 0: the object's colour C, no lights; docs/scene-format.md) under the
// canonical camera (eye (0,0,1) looking along -z, screen [-1,1]^2 at z = 0), 33x33 pixels:
// pixel (i, j) is centred on x = -1 + (2i+1)/33, y = 1 - (2j+1)/33.
//  * corners (0,0), (32,0), (0,32), (32,32): x, y = +-32/33; the ray (+-0.97, +-0.97, -1)
//    passes the sphere's centre (0,0,-2) at distance 2.4 > 1 and misses the cube: background.
//  * centre (16,16): the ray (0,0,-1) meets the unit sphere centred at (0,0,-2): 1, 0.2, 0.
//  * (12,12): x = -8/33, y = 8/33; along (x, y, -1) the plane z = -0.75 (the cube's front
//    face, cube [-0.75,-0.25] x [0.25,0.75] x [-1.25,-0.75]) is reached at 1.75 units of z,
//    at (-0.424, 0.424): inside the face, and in front of the sphere (whose nearest point is
//    at z = -1): 0, 1, 0. Its mirror image (12,20) is not green, so a flipped image fails.
// 8-bit files: round(c * 255): 0.2 -> 51, 0.4 -> 102, 0.6 -> 153, exact in float too.
const char* kFlatScene =
    "image width=33 height=33 spp=1 depth=0 degree=0\n"
    "camera\n"
    "background 0.2,0.4,0.6\n"
    "sphere color=1,0.2,0 translate=0,0,-2\n"
    "cube color=0,1,0 scale=0.25 translate=-0.5,0.5,-1\n";

struct Rgb8 {
    int w = 0, h = 0;
    std::vector<std::array<double, 3>> px;  // top row first, in [0, 1] (8-bit) or linear (PFM)
    std::array<double, 3> at(int x, int y) const { return px[std::size_t(y) * std::size_t(w) + std::size_t(x)]; }
};

/// PPM (P6, maxval 255) and PFM ("PF", little-endian, rows bottom-up), parsed here, not by
/// the code under test; PNG through stb_image.
Rgb8 read_back(const fs::path& p) {
    Rgb8 img;
    const std::string data = slurp(p);
    const std::string ext = p.extension().string();
    if (ext == ".png") {
        int n = 0;
        unsigned char* px = stbi_load_from_memory(reinterpret_cast<const unsigned char*>(data.data()), int(data.size()),
                                                  &img.w, &img.h, &n, 3);
        REQUIRE(px != nullptr);
        for (int i = 0; i < img.w * img.h; ++i)
            img.px.push_back({px[3 * i] / 255.0, px[3 * i + 1] / 255.0, px[3 * i + 2] / 255.0});
        stbi_image_free(px);
        return img;
    }
    std::istringstream in(data);
    std::string magic;
    double third = 0;
    in >> magic >> img.w >> img.h >> third;
    in.get();  // the one whitespace byte after the header
    const std::size_t start = std::size_t(in.tellg());
    const std::size_t n = std::size_t(img.w) * std::size_t(img.h);
    img.px.resize(n);
    if (magic == "P6") {
        REQUIRE(third == 255);
        REQUIRE(data.size() == start + 3 * n);
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) img.px[i][std::size_t(c)] = static_cast<unsigned char>(data[start + 3 * i + std::size_t(c)]) / 255.0;
    } else {
        REQUIRE(magic == "PF");
        REQUIRE(third < 0);  // little-endian, as this machine
        REQUIRE(data.size() == start + 12 * n);
        for (int y = 0; y < img.h; ++y)  // file row y counts from the bottom
            for (int x = 0; x < img.w; ++x)
                for (int c = 0; c < 3; ++c) {
                    float v;
                    std::memcpy(&v, data.data() + start + 12 * (std::size_t(y) * std::size_t(img.w) + std::size_t(x)) + 4 * std::size_t(c), 4);
                    img.px[std::size_t(img.h - 1 - y) * std::size_t(img.w) + std::size_t(x)][std::size_t(c)] = v;
                }
    }
    return img;
}

void check_pixel(const Rgb8& img, int x, int y, std::array<double, 3> want, double tol) {
    CAPTURE(x);
    CAPTURE(y);
    const auto got = img.at(x, y);
    for (int c = 0; c < 3; ++c) {
        CAPTURE(c);
        CHECK(std::abs(got[std::size_t(c)] - want[std::size_t(c)]) <= tol);
    }
}

}  // namespace

TEST_CASE("cli: a render writes the image with the scene's colours and leaves no temporary file") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kFlatScene);
    // PNG and PPM are sRGB-encoded by default; "--colorspace linear" gives the handout's
    // bytes, the linear colour itself; PFM holds the linear floats.
    for (const std::string ext : {".png", ".ppm", ".pfm", "_linear.ppm"}) {
        const fs::path out = d.path / ("img" + ext);
        const bool linear = ext == ".pfm" || ext == "_linear.ppm";
        const Run r = run_streamrt("-q -j2 " + q(scene) + " -o " + q(out) + (linear ? " --colorspace linear" : ""));
        INFO(ext, ": ", r.err);
        REQUIRE(r.code == 0);
        const Rgb8 img = read_back(out);
        REQUIRE(img.w == 33);
        REQUIRE(img.h == 33);
        // 8-bit: the exact byte; PFM: the float colour (exact: degree 0 copies C).
        const double tol = ext == ".pfm" ? 1e-6 : 0.1 / 255;
        std::array<double, 3> bg{0.2, 0.4, 0.6}, red{1, 0.2, 0}, green{0, 1, 0};
        if (!linear) {
            // 255 (1.055 c^(1/2.4) - 0.055): 0.2 -> 123.55, 0.4 -> 169.63, 0.6 -> 203.42.
            bg = {124 / 255.0, 170 / 255.0, 203 / 255.0};
            red = {1, 124 / 255.0, 0};
        }
        for (auto [x, y] : {std::pair{0, 0}, {32, 0}, {0, 32}, {32, 32}}) check_pixel(img, x, y, bg, tol);
        check_pixel(img, 16, 16, red, tol);
        check_pixel(img, 12, 12, green, tol);
        CHECK(img.at(12, 20)[1] < 0.5);  // the mirror image of (12,12) is not the cube
    }
    CHECK(d.files().size() == 5);  // the scene and the four images, nothing else
}

TEST_CASE("cli: .exr output, the display colour flags and their bad values") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kFlatScene);
    REQUIRE(run_streamrt("-q -j2 " + q(scene) + " -o " + q(d.path / "ref.pfm")).code == 0);
    const streamrt::Framebuffer ref = streamrt::read_image((d.path / "ref.pfm").string());
    // EXR (half by default): the linear floats to half's 11 significant bits, whatever the
    // display flags (they concern the 8-bit formats).
    const Run r = run_streamrt("-q -j2 --exposure 4 --tonemap reinhard " + q(scene) + " -o " + q(d.path / "img.exr"));
    INFO(r.err);
    REQUIRE(r.code == 0);
    const streamrt::Framebuffer exr = streamrt::read_image((d.path / "img.exr").string());
    REQUIRE(exr.rgb.size() == ref.rgb.size());
    for (std::size_t i = 0; i < ref.rgb.size(); ++i) CHECK(std::abs(exr.rgb[i] - ref.rgb[i]) <= ref.rgb[i] / 2048);
    // --exposure 2 --tonemap reinhard --colorspace linear: the background's 0.2 -> 0.4 ->
    // 0.4 / 1.4 = 0.285714 -> 72.86 -> 73; 0.4 -> 0.8 / 1.8 -> 113.33 -> 113; 0.6 -> 1.2 / 2.2 -> 139.09 -> 139.
    const fs::path ppm = d.path / "t.ppm";
    REQUIRE(run_streamrt("-q --exposure 2 --tonemap reinhard --colorspace linear " + q(scene) + " -o " + q(ppm)).code == 0);
    const std::string data = slurp(ppm);
    CHECK(data.substr(13, 3) == std::string("\x49\x71\x8b", 3));  // "P6\n33 33\n255\n" is 13 bytes
    for (const std::string bad : {"--exposure 0", "--exposure -1", "--tonemap aces", "--colorspace rgb"}) {
        const Run b = run_streamrt(bad + " " + q(scene) + " -o " + q(d.path / "no.png"));
        INFO(bad, ": ", b.err);
        CHECK(b.code == 2);
        CHECK(!fs::exists(d.path / "no.png"));
    }
}

TEST_CASE("cli: the summary line gives the process's phases, releasing the scene's records changes no pixel") {
    // Enough objects for the hierarchy, so the stream engine renders from its own records
    // after the command line has released the scene's.
    Dir d;
    std::string text = "image width=48 height=32 spp=1 depth=2 degree=5\ncamera eye=0,3,9 look=0,0,0\n"
                       "light point pos=5,8,5\nplane color=0.8,0.8,0.8 checker=0.2,0.2,0.2\n";
    for (int i = 0; i < 30; ++i)
        text += "sphere color=" + std::to_string(0.03 * i) + ",0.5,0.7 refl=0.2 scale=0.3 translate=" +
                std::to_string(i % 6 - 2.5) + ",0.3," + std::to_string(i / 6 - 2) + "\n";
    const fs::path scene = d.write("many.cfg", text);
    const fs::path out = d.path / "many.pfm";
    const Run r = run_streamrt("-j2 " + q(scene) + " -o " + q(out));
    INFO(r.out, r.err);
    REQUIRE(r.code == 0);
    for (const char* phase : {"(read ", ", set-up ", ", render ", ", write "}) CHECK(r.out.find(phase) != std::string::npos);
    check_same_as_in_process_stream(scene, out);
}

TEST_CASE("cli: --compare writes the stream engine's picture and honours --profile, the profile JSON is written whole") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    const fs::path out = d.path / "cmp.pfm", json = d.path / "prof.json";
    const Run r = run_streamrt("-j2 --compare --profile --profile-json " + q(json) + " " + q(scene) + " -o " + q(out));
    INFO(r.out, r.err);
    REQUIRE(r.code == 0);
    CHECK(r.out.find("speedup:") != std::string::npos);
    CHECK(r.out.find("stream profile:") != std::string::npos);
    // It ends, as every render does (README), with the summary line: the stream engine's, whose
    // picture was written, after the comparison and the profile.
    const std::size_t last = r.out.rfind('\n', r.out.size() - 2);
    const std::string summary = r.out.substr(last == std::string::npos ? 0 : last + 1);
    CHECK(summary.rfind(scene.string() + ": 32x24, spp 1, degree 5, stream engine, compared with the recursive engine, -j2: ",
                        0) == 0);
    CHECK(summary.find(" -> " + out.string() + " (read ") != std::string::npos);
    check_same_as_in_process_stream(scene, out);
    const std::string j = slurp(json);
    CHECK(j.rfind("{", 0) == 0);
    CHECK(j.find("\"stages\"") != std::string::npos);
    CHECK(d.files().size() == 3);  // the scene, the image, the profile: no temporary left
}

TEST_CASE("cli: --isa with the recursive engine and a profile into a missing folder are refused before rendering") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    const Run isa = run_streamrt("--engine recursive --isa sse2 " + q(scene) + " -o " + q(d.path / "a.png"));
    CHECK(isa.code == 2);
    check_one_line_error(isa, "--isa");
    const Run prof = run_streamrt("--profile-json " + q(d.path / "missing" / "p.json") + " " + q(scene) + " -o " +
                                  q(d.path / "b.png"));
    CHECK(prof.code == 2);
    check_one_line_error(prof, "does not exist");
    CHECK(d.files().size() == 1);  // nothing rendered, nothing written
}

TEST_CASE("cli: the PNG file's bytes are the same at -j1 and -j2") {
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    // 400 wide: 110-row PNG bands, so 300 rows are three bands encoded in parallel at -j2.
    std::string bytes[2];
    for (int j = 1; j <= 2; ++j) {
        const fs::path out = d.path / ("j" + std::to_string(j) + ".png");
        const Run r = run_streamrt("-q -j" + std::to_string(j) + " --width 400 --height 300 " + q(scene) + " -o " + q(out));
        REQUIRE(r.code == 0);
        bytes[j - 1] = slurp(out);
    }
    CHECK(bytes[0].size() > 1000);
    CHECK(bytes[0] == bytes[1]);
}

TEST_CASE("cli: a 32768x32768 render fits a 24 GiB machine: --check says ok") {
    // 12 GiB of float framebuffer plus the writer's bands (about 13 MiB), not 18 GiB of copies.
    const double memory = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGE_SIZE));
    if (memory < 20.0 * (1ull << 30)) return;  // a smaller machine rightly refuses it
    Dir d;
    const fs::path scene = d.write("s.cfg", kSmallScene);
    const Run r = run_streamrt("--check -j2 --width 32768 --height 32768 " + q(scene) + " -o " + q(d.path / "big.png"));
    INFO(r.err);
    CHECK(r.code == 0);
    CHECK(r.out.find("ok") != std::string::npos);
}

namespace {

/// Starts streamrt with argv in a child (stdout and stderr to `log`), returns its pid. With
/// `fifo_for`, the child first makes a FIFO at the temporary name the image writer will use
/// for that output (engine/image/image_io.cpp: ".NAME.tmpPID" in the output's folder; the pid
/// is the child's, kept across exec), so the writer's open() and writes meet this test.
pid_t spawn(const std::vector<std::string>& args, const fs::path& log, const fs::path& fifo_for = {}) {
    std::fflush(nullptr);  // or the child would flush our buffered output again
    const pid_t pid = ::fork();
    if (pid == 0) {
        if (!fifo_for.empty()) {
            const fs::path fifo = fifo_for.parent_path() / ("." + fifo_for.filename().string() + ".tmp" + std::to_string(::getpid()));
            if (::mkfifo(fifo.c_str(), 0600) != 0) ::_exit(97);
        }
        if (!std::freopen(log.c_str(), "w", stderr) || !std::freopen("/dev/null", "w", stdout)) ::_exit(99);
        std::vector<char*> argv;
        argv.push_back(const_cast<char*>(STREAMRT_BINARY));
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(STREAMRT_BINARY, argv.data());
        ::_exit(98);
    }
    return pid;
}

/// Waits until the child runs streamrt (/proc/PID/exe; before exec it is a copy of this test
/// program, with doctest's own SIGINT handler) and streamrt has installed its SIGINT handler
/// (bit 2 of SigCgt in /proc/PID/status), so that a SIGINT sent afterwards is the program's
/// to handle, not the default action's. No clock: it polls until then or the child's end.
bool wait_for_sigint_handler(pid_t pid) {
    const std::string proc = "/proc/" + std::to_string(pid);
    const fs::path binary = fs::canonical(STREAMRT_BINARY);
    for (;;) {
        std::error_code ec;
        const bool execed = fs::read_symlink(proc + "/exe", ec) == binary;
        std::ifstream st(proc + "/status");
        std::string line;
        while (std::getline(st, line))
            if (execed && line.rfind("SigCgt:", 0) == 0) {
                const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
                if (mask & (1ull << (SIGINT - 1))) return true;
            }
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid) return false;  // ended before
        ::usleep(1000);
    }
}

/// Blocks until the child ends; its wait status.
int wait_child(pid_t pid) {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
}

// Long enough that it is still rendering when interrupted (the interrupt is sent as soon as
// the handler is installed, before the scene is even read on a fast machine).
const char* kLongScene =
    "image width=2048 height=2048 spp=64 depth=8 degree=5 output=long.png\n"
    "camera eye=0,1,6 look=0,0,0\n"
    "light point pos=5,8,5\nlight point pos=-5,8,5\n"
    "material glass refl=0.3 trans=0.6 ior=1.5\n"
    "sphere material=glass\ncube translate=2,0,0 refl=0.5\nplane translate=0,-1,0 checker=0,0,0\n";

/// Interrupts the writing of `out` (a render of kFlatScene at w x h): the writer's temporary
/// is a FIFO made by the child; this test opens its reading end, waits for the first bytes
/// (the writer is then inside its write loop), sends SIGINT, and only then drains the FIFO.
/// More than the pipe's 64 KiB is written, so the writer is blocked in write() when the
/// signal is sent and cannot go on before the handler has run: deterministic, no clock.
/// Returns the exit status; `drained` gets the bytes the writer wrote.
int interrupt_during_write(const Dir& d, const fs::path& out, int w, int h, std::size_t& drained, std::string& err) {
    const fs::path scene = d.write("flat.cfg", kFlatScene);
    const pid_t pid = spawn({"-q", "-j2", "--width", std::to_string(w), "--height", std::to_string(h), scene.string(),
                             "-o", out.string()},
                            d.path / "log", out);
    REQUIRE(pid > 0);
    const fs::path fifo = out.parent_path() / ("." + out.filename().string() + ".tmp" + std::to_string(pid));
    // The child makes the FIFO before exec: wait for it (or for the child's end).
    int fd = -1;
    while ((fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK)) < 0) {
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid) FAIL("the child ended before making its FIFO, status " << status);
        ::usleep(1000);
    }
    // Wait for the first bytes: the writer has opened the temporary and is writing.
    char buf[65536];
    drained = 0;
    for (;;) {
        const ssize_t n = ::read(fd, buf, 1);
        if (n == 1) {
            drained = 1;
            break;
        }
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            ::close(fd);
            err = slurp(d.path / "log");
            FAIL("the child ended before writing, status " << status << ", stderr: " << err);
        }
        ::usleep(1000);
    }
    REQUIRE(::kill(pid, SIGINT) == 0);
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    for (;;) {  // drain until the writer closes its end
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n > 0) drained += std::size_t(n);
        else if (n == 0 || errno != EINTR) break;
    }
    ::close(fd);
    const int status = wait_child(pid);
    err = slurp(d.path / "log");
    fs::remove(d.path / "log");
    return status;
}

}  // namespace

TEST_CASE("cli: Ctrl-C during the render: exit 130, no image and no temporary file") {
    // No clock: SIGINT is sent once the handler is installed; the render (seconds long) is
    // then in its set-up or its tiles, never past them. How fast it stops is not asserted (no
    // timed tests; the render loop polls the flag between chunks, stream/stream_renderer.h).
    for (const std::string engine : {"stream", "recursive"}) {
        Dir d;
        const fs::path scene = d.write("long.cfg", kLongScene);
        const fs::path out = d.path / "long.png";
        const pid_t pid = spawn({"-j2", "--engine", engine, scene.string(), "-o", out.string()}, d.path / "log");
        REQUIRE(pid > 0);
        REQUIRE(wait_for_sigint_handler(pid));
        REQUIRE(::kill(pid, SIGINT) == 0);
        const int status = wait_child(pid);
        const std::string err = slurp(d.path / "log");
        INFO(engine, ": stderr: ", err);
        CHECK(WIFEXITED(status));
        CHECK(WEXITSTATUS(status) == 130);
        CHECK(err == "streamrt: interrupted, no image written\n");
        CHECK(!fs::exists(out));
        fs::remove(d.path / "log");
        CHECK(d.files() == std::vector<std::string>{"long.cfg"});
    }
}

TEST_CASE("cli: Ctrl-C while the image is being written: exit 130, no image and no temporary file") {
    // 1500 x 1000 PPM: 4.5 MB, two of the writer's 4 MiB chunks; SIGINT arrives while the
    // first chunk is written (blocked on the FIFO), and the writer looks at the flag before
    // the second: the path from a cancelled write to the unlink of the temporary and
    // Interrupted (exit 130) in the command, with the rename never reached.
    Dir d;
    const fs::path out = d.path / "big.ppm";
    std::size_t drained = 0;
    std::string err;
    const int status = interrupt_during_write(d, out, 1500, 1000, drained, err);
    INFO("stderr: ", err, "; bytes written before stopping: ", drained);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 130);
    CHECK(err == "streamrt: interrupted, no image written\n");
    CHECK(drained < std::size_t(1500) * 1000 * 3);  // stopped before the end
    CHECK(!fs::exists(out));
    CHECK(d.files() == std::vector<std::string>{"flat.cfg"});  // the FIFO (the temporary) is gone
}

TEST_CASE("cli: Ctrl-C during the last write of an image: exit 130, no image") {
    // A PFM is written in one writev with no look at the flag on the way: the writer looks
    // at it once more before the rename (image_io.cpp, write_atomically).
    Dir d;
    const fs::path out = d.path / "small.pfm";
    std::size_t drained = 0;
    std::string err;
    const int status = interrupt_during_write(d, out, 256, 256, drained, err);
    INFO("stderr: ", err, "; bytes written: ", drained);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 130);
    CHECK(!fs::exists(out));
    CHECK(d.files() == std::vector<std::string>{"flat.cfg"});
}

TEST_CASE("cli: a killed render leaves no image and no temporary file") {
    Dir d;
    const fs::path scene = d.write("long.cfg", kLongScene);
    const pid_t pid = spawn({"-j2", scene.string(), "-o", (d.path / "long.png").string()}, "/dev/null");
    REQUIRE(pid > 0);
    REQUIRE(wait_for_sigint_handler(pid));  // past start-up: reading, set-up or rendering
    ::kill(pid, SIGKILL);
    const int status = wait_child(pid);
    CHECK(WIFSIGNALED(status));
    CHECK(d.files() == std::vector<std::string>{"long.cfg"});
}

TEST_CASE("cli: checking the output folder names no file there (a kill at any moment leaves nothing)") {
    // The writability probe used to be a named file created and removed at once: a SIGKILL
    // between the two left it behind (seen as a rare failure of the killed-render test
    // above). Every file created in the folder during --check is recorded by inotify.
    Dir d;
    const fs::path scene = d.write("s.cfg", "image width=4 height=4\nsphere\n");
    const int in = ::inotify_init1(IN_NONBLOCK);
    REQUIRE(in >= 0);
    REQUIRE(::inotify_add_watch(in, d.path.c_str(), IN_CREATE | IN_MOVED_TO) >= 0);
    const Run r = run_streamrt("--check " + q(scene) + " -o " + q(d.path / "out.png"));
    CHECK(r.code == 0);
    std::vector<std::string> created;
    alignas(inotify_event) char buf[4096];
    for (ssize_t n; (n = ::read(in, buf, sizeof buf)) > 0;)
        for (const char* p = buf; p < buf + n;) {
            const auto* e = reinterpret_cast<const inotify_event*>(p);
            if (e->len) created.emplace_back(e->name);
            p += sizeof(inotify_event) + e->len;
        }
    ::close(in);
    CHECK(created == std::vector<std::string>{});
}

// ---- animation: --frames, image frames=, output patterns, shards of a frame ----------------
namespace {

const char* kAnimScene =
    "image width=40 height=20 spp=1 depth=1 degree=5 output=out.pfm\n"
    "camera eye=0,0,6 look=0,0,0 fov=40\n"
    "light point pos=5,8,5\n"
    "sphere name=ball color=1,0.2,0.1 scale=0.6\n"
    "key ball frame=0 translate=-2,0,0\n"
    "key ball frame=10 translate=2,0,0\n";

/// The column average of the pixels the red ball covers (red well above green).
double ball_column(const streamrt::Framebuffer& img) {
    double sum = 0, n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (img.pixel(x, y)[0] > img.pixel(x, y)[1] + 0.2f) sum += x, n += 1;
    REQUIRE(n > 0);
    return sum / n;
}

}  // namespace

TEST_CASE("cli: --frames A..B writes one picture per frame to the %d pattern") {
    Dir d;
    const fs::path scene = d.write("a.cfg", kAnimScene);
    const Run r = run_streamrt("-q " + q(scene) + " --frames 2..4 -o " + q(d.path / "out_%04d.pfm"));
    REQUIRE(r.code == 0);
    CHECK(!fs::exists(d.path / "out_0001.pfm"));
    CHECK(!fs::exists(d.path / "out_0005.pfm"));
    double previous = -1;
    for (int f = 2; f <= 4; ++f) {
        CAPTURE(f);
        const fs::path out = d.path / ("out_000" + std::to_string(f) + ".pfm");
        REQUIRE(fs::exists(out));
        const streamrt::Framebuffer written = streamrt::read_image(out.string());
        // The frame the command wrote is the scene put at that frame, rendered here.
        streamrt::Scene at = streamrt::load_scene(scene.string());
        streamrt::set_frame(at, f);
        streamrt::Parallelism par(2);
        const streamrt::Framebuffer here = streamrt::render_scene(at, streamrt::EngineKind::Stream, par).image;
        CHECK(written.rgb == here.rgb);
        // The ball moves right by 0.4 units a frame.
        const double column = ball_column(written);
        CHECK(column > previous + 1.0);
        previous = column;
    }
    // image frames= in the scene does the same without --frames.
    const fs::path scene2 = d.write("b.cfg", std::string(kAnimScene) + "image frames=0..1 output=b_%d.pfm\n");
    const Run r2 = run_streamrt("-q " + q(scene2) + " -o " + q(d.path / "b_%d.pfm"));
    CHECK(r2.code == 0);
    CHECK(fs::exists(d.path / "b_0.pfm"));
    CHECK(fs::exists(d.path / "b_1.pfm"));
}

TEST_CASE("cli: bad frame ranges and output names are one-line errors, exit 2") {
    Dir d;
    const fs::path scene = d.write("a.cfg", kAnimScene);
    const Run back = run_streamrt(q(scene) + " --frames 10..2 -o " + q(d.path / "o_%d.png"));
    CHECK(back.code == 2);
    check_one_line_error(back, "--frames 10..2: the range 10..2 runs backwards");
    const Run neg = run_streamrt(q(scene) + " --frames -1..2 -o " + q(d.path / "o_%d.png"));
    CHECK(neg.code == 2);
    const Run nopattern = run_streamrt(q(scene) + " --frames 2..4 -o " + q(d.path / "o.png"));
    CHECK(nopattern.code == 2);
    check_one_line_error(nopattern, "several frames need one printf-style frame number in the name");
    const fs::path bad = d.write("bad.cfg", std::string(kAnimScene) + "key nobody frame=2 translate=0,1,0\n");
    const Run unknown = run_streamrt(q(bad) + " -o " + q(d.path / "o.png"));
    CHECK(unknown.code == 2);
    check_one_line_error(unknown, bad.string() + ":7:5: key for an unknown name 'nobody'");
    const fs::path back2 = d.write("back.cfg", std::string(kAnimScene) + "image frames=10..2\n");
    const Run r = run_streamrt(q(back2) + " -o " + q(d.path / "o_%d.png"));
    CHECK(r.code == 2);
    check_one_line_error(r, back2.string() + ":7:14: 'frames': the range 10..2 runs backwards");
    CHECK(d.files().size() == 3);  // the scenes only: nothing written
}

TEST_CASE("cli: --frames composes with --shard: the merged parts of a frame are that frame") {
    Dir d;
    const fs::path scene = d.write("a.cfg", kAnimScene);
    for (int k = 0; k < 2; ++k) {
        const Run r = run_streamrt("-q " + q(scene) + " --frames 2..3 --shard " + std::to_string(k) + "/2 -o " +
                                   q(d.path / ("p" + std::to_string(k) + "_%04d.part")));
        REQUIRE(r.code == 0);
    }
    const Run whole = run_streamrt("-q " + q(scene) + " --frames 3 -o " + q(d.path / "whole_%d.pfm"));
    REQUIRE(whole.code == 0);
    const Run m = run_streamrt("merge -q " + q(d.path / "p0_0003.part") + " " + q(d.path / "p1_0003.part") + " -o " +
                               q(d.path / "merged3.pfm"));
    REQUIRE(m.code == 0);
    CHECK(slurp(d.path / "merged3.pfm") == slurp(d.path / "whole_3.pfm"));
    // Parts of different frames do not merge.
    const Run mixed = run_streamrt("merge -q " + q(d.path / "p0_0002.part") + " " + q(d.path / "p1_0003.part") +
                                   " -o " + q(d.path / "mixed.pfm"));
    CHECK(mixed.code == 2);
}

TEST_CASE("cli: --light-samples overrides every area light's samples") {
    Dir d;
    const fs::path scene = d.write("area.cfg", "image width=16 height=12 spp=1 depth=0 degree=5\n"
                                               "camera eye=0,1,6 look=0,0,0\n"
                                               "light sphere pos=3,5,4 radius=1 samples=9\n"
                                               "light rect pos=-3,5,0 u=1,0,0 v=0,0,1 samples=4\n"
                                               "light point pos=0,5,5\n"
                                               "sphere color=1,0,0\nplane translate=0,-1,0\n");
    const Run as_is = run_streamrt(q(scene) + " --profile -o " + q(d.path / "a.png"));
    CHECK(as_is.code == 0);
    CHECK(as_is.out.find("occlusion(any-hit,area x 13)") != std::string::npos);
    const Run three = run_streamrt(q(scene) + " --light-samples 3 --profile -o " + q(d.path / "b.png"));
    CHECK(three.code == 0);
    CHECK(three.out.find("occlusion(any-hit,area x 6)") != std::string::npos);
    const Run zero = run_streamrt(q(scene) + " --light-samples 0 -o " + q(d.path / "c.png"));
    CHECK(zero.code == 2);
    INFO("stderr: ", zero.err);
    CHECK(zero.err.find("--light-samples") != std::string::npos);
}
