// The memory estimate and the refusal of renders that cannot fit (driver/limits.h).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "driver/limits.h"
#include "scene/parser.h"

using namespace streamrt;

TEST_CASE("limits: the estimate counts the framebuffer, the output and the per-thread streams") {
    Scene sc = parse_scene("image width=100 height=50 spp=1 depth=5 degree=5\nsphere\n", "t.cfg");
    const MemoryEstimate e = estimate_render_memory(sc, true, 4);
    CHECK(e.framebuffer_bytes == 100.0 * 50 * 3 * 4);
    // One PNG band (the whole image): two 8-bit rows 600, filtered rows 50 * 301, their
    // deflate bound 15050 + 16 + 64, one deflate state 270336. PNG needs the most.
    CHECK(e.output_bytes == 600 + 15050 + 15130 + 270336);
    CHECK(e.branching == 1);
    CHECK(e.peak_stream_rays == 4096);  // no mirror: the stream never grows
    CHECK(e.threads == 4);
    CHECK(e.total_bytes == doctest::Approx(e.framebuffer_bytes + e.output_bytes + 4 * e.per_thread_bytes));

    // spp above the chunk size: one pixel's samples are one chunk.
    sc.settings.spp = 65536;
    CHECK(estimate_render_memory(sc, true, 1).peak_stream_rays == 65536);
}

TEST_CASE("limits: 2^depth secondaries only when one material both reflects and transmits") {
    Scene mirror = parse_scene("image depth=10\nsphere refl=0.5\ncube trans=0.5\n", "t.cfg");
    CHECK(estimate_render_memory(mirror, true, 1).branching == 1);
    Scene glass = parse_scene("image depth=10\nsphere refl=0.5 trans=0.5\n", "t.cfg");
    const MemoryEstimate e = estimate_render_memory(glass, true, 1);
    CHECK(e.branching == 2);
    CHECK(e.peak_stream_rays == 4096.0 * 1024);
    glass.settings.degree = 3;  // no refraction below degree 4
    CHECK(estimate_render_memory(glass, true, 1).branching == 1);
    // The recursive engine's memory does not grow with 2^depth.
    glass.settings.degree = 5;
    glass.settings.depth = 256;
    CHECK(estimate_render_memory(glass, false, 1).total_bytes < 1e8);
    CHECK(std::isfinite(estimate_render_memory(glass, true, 1).total_bytes));  // 2^256 fits a double
}

TEST_CASE("limits: a render above the limit is refused with what it would need") {
    Scene sc = parse_scene("image width=32768 height=32768\nsphere\n", "t.cfg");
    CHECK_NOTHROW(check_render_memory(sc, true, 2, 1e12));
    // The writer streams bands: 16 bands of 2 rows in flight, not a copy of the image, so
    // the 12 GiB framebuffer fits a 24 GiB machine.
    const MemoryEstimate big = estimate_render_memory(sc, true, 2);
    CHECK(big.output_bytes == 16.0 * (2 * 98304 + 2 * 98305 + (2 * 98305 + 197 + 64) + 270336));
    CHECK_NOTHROW(check_render_memory(sc, true, 2, 24.0 * 1024 * 1024 * 1024));
    try {
        check_render_memory(sc, true, 2, 8.0 * 1024 * 1024 * 1024);
        FAIL("expected a UsageError");
    } catch (const UsageError& e) {
        const std::string m = e.what();
        CHECK(m.find("image 32768x32768, spp 1, depth 5 would need about 12.0 GiB of memory") == 0);
        CHECK(m.find("framebuffer 12.0 GiB") != std::string::npos);
        CHECK(m.find("but this machine has 8.0 GiB") != std::string::npos);
        CHECK(m.find('\n') == std::string::npos);
    }
    Scene deep = parse_scene("image depth=256\nsphere refl=0.5 trans=0.5\n", "t.cfg");
    CHECK_THROWS_AS(check_render_memory(deep, true, 1), UsageError);  // the real machine
    CHECK_NOTHROW(check_render_memory(deep, false, 1));
    CHECK(physical_memory_bytes() > 0);
}

TEST_CASE("limits: format_bytes") {
    CHECK(format_bytes(512) == "512 bytes");
    CHECK(format_bytes(1536) == "1.5 KiB");
    CHECK(format_bytes(12.0 * 1024 * 1024 * 1024) == "12.0 GiB");
    CHECK(format_bytes(std::pow(2.0, 256)).find("e+") != std::string::npos);
}

TEST_CASE("limits: the parser caps absurd values (width 1e9, depth 1e6, spp 1e8)") {
    for (const char* text : {"image width=1e9\n", "image height=1000000000\n", "image depth=1e6\n",
                             "image spp=1e8\n", "image degree=6\n", "image width=2147483648\n",
                             "image width=-1\n", "image spp=1e308\n"}) {
        INFO(text);
        CHECK_THROWS_AS(parse_scene(text, "t.cfg"), SceneError);
    }
}
