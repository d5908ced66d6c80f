// Any depth in bounded memory (issue 11, item 4): the stream engine traces generations
// deepest first in slices of whole pixels (stream/stages.h, trace_generation), so the
// picture does not change and the rays held stay bounded by the slice size times the levels.
#include <doctest/doctest.h>

#include <sys/ptrace.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "driver/render.h"
#include "image/image_compare.h"
#include "parallel/parallelism.h"
#include "scene/parser.h"
#include "stream/child_peak_rss.h"

using namespace streamrt;
using streamrt::test::child_peak_rss_kib;
namespace fs = std::filesystem;

namespace {

const std::string kWhitted = std::string(STREAMRT_SOURCE_DIR) + "/scenes/whitted.cfg";

Scene whitted(int width, int height, int spp, int depth) {
    Scene s = load_scene(kWhitted);
    s.settings.width = width;
    s.settings.height = height;
    s.settings.spp = spp;
    s.settings.depth = depth;
    return s;
}

/// The picture of `s`; slice_rays and shade as EngineOptions has them.
Framebuffer render_with(const Scene& s, EngineKind engine, int jobs, std::size_t slice_rays = 0,
                        ShadeMode shade = ShadeMode::Auto) {
    EngineOptions options;
    options.shade = shade;
    options.slice_rays = slice_rays;
    Parallelism threads(jobs);
    return render_scene(s, engine, threads, nullptr, options).image;
}

bool same_bits(const Framebuffer& a, const Framebuffer& b) {
    return a.width == b.width && a.height == b.height &&
           std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

}  // namespace

TEST_CASE("depth: the default slices leave the picture of whole generations, bit for bit") {
    // At 64x48, spp 4, depth 5 no generation of a chunk exceeds a default slice.
    const Scene s = whitted(64, 48, 4, 5);
    for (ShadeMode shade : {ShadeMode::Sorted, ShadeMode::Gathered, ShadeMode::Scalar}) {
        CAPTURE(int(shade));
        const Framebuffer whole = render_with(s, EngineKind::Stream, 2, 1u << 20, shade);
        CHECK(same_bits(render_with(s, EngineKind::Stream, 2, 0, shade), whole));
    }
}

TEST_CASE("depth: slices of whole pixels give one pixel its additions in the same order") {
    // At spp 4 and depth 5 a pixel has at most 4 x 2^5 = 128 rays in a generation: with
    // slices of 128 or 200 rays generations are cut, pixels never. Each pixel then sums the
    // same terms in the same order: bit-identical, one ray at a time (scalar shading) and in
    // the SIMD kernels, whose children join the next stream by kind and whose shadow rays add
    // their light into their hit, wherever the packets are cut (ShadeJob::next). Whitted's two
    // lights and its glass sphere give a hit two shadow rays and two children, and its rays
    // share runs with other pixels' rays: appended packet by packet, light by light and kind by
    // kind, the cuts moved a pixel's sums by up to an ulp.
    const Scene s = whitted(64, 48, 4, 5);
    for (ShadeMode shade : {ShadeMode::Scalar, ShadeMode::Sorted, ShadeMode::Gathered}) {
        CAPTURE(int(shade));
        const Framebuffer whole = render_with(s, EngineKind::Stream, 2, 1u << 20, shade);
        CHECK(same_bits(render_with(s, EngineKind::Stream, 2, 128, shade), whole));
        CHECK(same_bits(render_with(s, EngineKind::Stream, 1, 200, shade), whole));
    }
}

TEST_CASE("depth: slices smaller than a pixel's rays stay deterministic and close") {
    // Slices of 3 rays cut every pixel: its additions then come in another (fixed) order.
    const Scene s = whitted(48, 32, 4, 6);
    const Framebuffer whole = render_with(s, EngineKind::Stream, 2);
    const Framebuffer tiny1 = render_with(s, EngineKind::Stream, 1, 3);
    const Framebuffer tiny2 = render_with(s, EngineKind::Stream, 2, 3);
    CHECK(same_bits(tiny1, tiny2));
    CHECK(same_bits(tiny1, render_with(s, EngineKind::Stream, 2, 3)));
    const ImageDifference d = compare_images(tiny1, whole);
    CAPTURE(d.max_abs);
    CHECK(d.max_abs < 1e-5);
}

TEST_CASE("depth: Whitted at depth 16, 32 and 256 renders and matches the recursive baseline") {
    for (int depth : {16, 32, 256}) {
        CAPTURE(depth);
        const Scene s = depth <= 32 ? whitted(96, 72, 2, depth) : whitted(48, 36, 1, depth);
        const Framebuffer stream = render_with(s, EngineKind::Stream, 2);
        const Framebuffer recursive = render_with(s, EngineKind::Recursive, 2);
        const ImageDifference d = compare_images(stream, recursive);
        MESSAGE("depth " << depth << ": PSNR " << d.psnr << " dB, max " << d.max_abs);
        CAPTURE(d.psnr);
        CHECK(d.psnr >= 50.0);
        CHECK(d.share_over <= 0.001);
    }
}

TEST_CASE("depth: peak memory at depth 16 and 32 stays within a few MB of depth 5") {
    const fs::path out = fs::temp_directory_path() / ("streamrt_depth_" + std::to_string(::getpid()) + ".pfm");
    const auto peak = [&](int depth) {
        return child_peak_rss_kib({kWhitted, "--width", "320", "--height", "180", "--spp", "4", "--depth",
                                   std::to_string(depth), "-j", "2", "-q", "-o", out.string()});
    };
    const long d5 = peak(5), d16 = peak(16), d32 = peak(32);
    if (d5 < 0) {
        WARN_MESSAGE(false, "ptrace(PTRACE_TRACEME) is not allowed here: peak memory not measured");
        return;
    }
    MESSAGE("peak RSS, KiB: depth 5 " << d5 << ", depth 16 " << d16 << ", depth 32 " << d32);
    CHECK(d16 - d5 < 3 * 1024);
    CHECK(d32 - d5 < 3 * 1024);
    fs::remove(out);
}
