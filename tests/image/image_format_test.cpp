// The output-format registry (image/image_format.h) and the Radiance HDR format added through
// it (image/hdr_format.cpp): bytes worked out by hand from the RGBE definition, round trips
// within the format's precision, and what every registered format must provide.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/image_io.h"

using namespace streamrt;
using namespace std::string_literals;
namespace fs = std::filesystem;

namespace {

fs::path temp_file(const std::string& name) { return fs::temp_directory_path() / ("streamrt_fmt_" + name); }

std::string file_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

Framebuffer filled(int w, int h, float r, float g, float b) {
    Framebuffer fb(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = fb.pixel(x, y);
            p[0] = r, p[1] = g, p[2] = b;
        }
    return fb;
}

const std::string kHeader8x1 = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nSOFTWARE=streamrt\n\n-Y 1 +X 8\n";

}  // namespace

// Proven against: the exponent stored without its bias of 128 (129 -> 1), and the channels
// of the run-length scanline written in the order B, G, R.
TEST_CASE("hdr: RGBE codes and the run-length scanline, worked out by hand") {
    // (1, 0.5, 0.25): the brightest channel 1 = 0.5 x 2^1, so e = 1 (stored 129) and each
    // mantissa is c x 256 / 2^1: 128, 64, 32. A row of 8 equal pixels (the smallest width that
    // takes the run-length form) is, per channel, one run of 8: count 128 + 8, then the value.
    const fs::path p = temp_file("8x1.hdr");
    REQUIRE(write_image(p, filled(8, 1, 1.f, 0.5f, 0.25f), Display{}));
    const std::string expected = kHeader8x1 + std::string{2, 2, 0, 8} + "\x88\x80" + "\x88\x40" + "\x88\x20" + "\x88\x81";
    CHECK(file_bytes(p) == expected);
    fs::remove(p);
}

// Proven against: flat pixels written for widths below 8 in the run-length form (the
// format has no such scanline; readers take it for pixels).
TEST_CASE("hdr: narrow images are written as flat RGBE pixels") {
    // 3 = 0.75 x 2^2: e = 2 (130), red 3 x 256 / 4 = 192; black is 0, 0, 0, 0.
    Framebuffer fb = filled(2, 1, 3.f, 0.f, 0.f);
    fb.pixel(1, 0)[0] = 0.f;
    const fs::path p = temp_file("2x1.hdr");
    REQUIRE(write_image(p, fb, Display{}));
    const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nSOFTWARE=streamrt\n\n-Y 1 +X 2\n";
    CHECK(file_bytes(p) == header + std::string{'\xc0', 0, 0, '\x82', 0, 0, 0, 0});
    fs::remove(p);
}

// Proven against: the decoder not adding the half code (values biased low by up to a code),
// and a literal stretch's count off by one in the encoder (the reader then runs off the row).
TEST_CASE("hdr: values read back within half a code of the brightest channel, every scanline form") {
    // Each pixel's channels are coded against its brightest one v = m 2^e, m in [0.5, 1): the
    // code step is 2^(e-8) <= v / 128, truncation loses less than a step and the reader takes
    // the step's middle, so |read - written| <= v / 256.
    for (int w : {3, 8, 37, 300}) {
        CAPTURE(w);
        Framebuffer fb(w, 5);
        for (std::size_t i = 0; i < fb.rgb.size(); ++i)
            fb.rgb[i] = i % 11 == 0 ? 0.f : std::exp2(float(int((i * 7919) % 40) - 20) / 3.f) * (i % 5 ? 1.f : 1.5f);
        for (int x = 0; x < w / 2; ++x) fb.pixel(x, 2)[0] = fb.pixel(x, 2)[1] = fb.pixel(x, 2)[2] = 0.375f;  // runs
        const fs::path p = temp_file("round.hdr");
        REQUIRE(write_image(p, fb, Display{}));
        const Framebuffer back = read_image(p);
        REQUIRE(back.width == w);
        REQUIRE(back.height == 5);
        for (int y = 0; y < fb.height; ++y)
            for (int x = 0; x < w; ++x) {
                const float* a = fb.pixel(x, y);
                const float* b = back.pixel(x, y);
                const float v = std::max({a[0], a[1], a[2]});
                for (int k = 0; k < 3; ++k) {
                    CAPTURE(x); CAPTURE(y); CAPTURE(k);
                    CHECK(std::abs(b[k] - a[k]) <= v / 256.f);
                }
            }
        fs::remove(p);
    }
}

TEST_CASE("hdr: values with no RGBE code are written as black, damaged files are refused") {
    Framebuffer fb = filled(8, 1, 1.f, 1.f, 1.f);
    fb.pixel(0, 0)[0] = -2.f;
    fb.pixel(1, 0)[1] = std::numeric_limits<float>::quiet_NaN();
    fb.pixel(2, 0)[2] = std::numeric_limits<float>::infinity();
    const fs::path p = temp_file("odd.hdr");
    REQUIRE(write_image(p, fb, Display{}));
    const Framebuffer back = read_image(p);
    // Written as code 0 beside channels of 1 (e = 1): read as the middle of the first step,
    // 0.5 x 2^(129 - 136) = 1/256, as Radiance reads it.
    CHECK(back.pixel(0, 0)[0] == 1.f / 256);
    CHECK(back.pixel(1, 0)[1] == 1.f / 256);
    CHECK(back.pixel(2, 0)[2] == 1.f / 256);
    // A black pixel (exponent code 0) is exactly black.
    REQUIRE(write_image(p, filled(8, 1, 0.f, 0.f, 0.f), Display{}));
    CHECK(read_image(p).pixel(3, 0)[1] == 0.f);
    REQUIRE(write_image(p, fb, Display{}));
    CHECK(back.pixel(2, 0)[0] == doctest::Approx(1.0).epsilon(1.0 / 256));
    // Cut inside the pixels, a foreign signature, another orientation.
    const std::string whole = file_bytes(p);
    for (const std::string& bad : {whole.substr(0, whole.size() - 3), "P6\n1 1\n255\n\x01\x02\x03"s,
                                   "#?RADIANCE\n\n+Y 1 +X 8\n" + whole.substr(kHeader8x1.size())}) {
        std::ofstream(p, std::ios::binary) << bad;
        CHECK_THROWS_AS(read_image(p), RenderError);
    }
    fs::remove(p);
}

// Proven against: a format missing from the list in image/image_formats.cpp (its extension is
// then unknown), and a format whose buffer estimate is left out of image_write_buffer_bytes.
TEST_CASE("image formats: every registered format writes, reads back and names itself") {
    const std::vector<std::string> expected{".ppm", ".png", ".pfm", ".exr", ".hdr"};
    REQUIRE(image_formats().size() == expected.size());
    CHECK(image_format_extensions() == ".ppm, .png, .pfm, .exr or .hdr");
    const Framebuffer fb = filled(9, 4, 0.25f, 0.5f, 0.75f);
    for (const ImageFormat* f : image_formats()) {
        CAPTURE(f->name);
        CHECK(std::find(expected.begin(), expected.end(), std::string(f->extension)) != expected.end());
        CHECK(image_format_for("x" + std::string(f->extension)) == f);
        std::string upper(f->extension);
        for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
        CHECK(image_format_for("dir.d/x" + upper) == f);  // case-insensitive
        CHECK(bool(f->encode) != bool(f->write_file));     // exactly one way to write
        CHECK(bool(f->read));
        CHECK(image_write_buffer_bytes(1000, 1000) >= f->buffer_bytes(1000, 1000));
        const fs::path p = temp_file("all" + std::string(f->extension));
        REQUIRE(write_image(p, fb, Display::raw(Calibration::Clamp)));
        const Framebuffer back = read_image(p);
        REQUIRE(back.width == 9);
        REQUIRE(back.height == 4);
        // Linear raw output: 8-bit codes round to 1/510, RGBE to 1/256 of the brightest channel.
        for (std::size_t i = 0; i < back.rgb.size(); ++i) CHECK(back.rgb[i] == doctest::Approx(fb.rgb[i]).epsilon(0.004));
        fs::remove(p);
    }
    CHECK(image_format_for("x.bmp") == nullptr);
    CHECK_THROWS_AS(image_format(".bmp"), std::invalid_argument);
    try {
        write_image(temp_file("x.bmp"), fb, Display{});
        FAIL("expected a RenderError");
    } catch (const RenderError& e) {
        CHECK(std::string(e.what()).find("(expected .ppm, .png, .pfm, .exr or .hdr)") != std::string::npos);
    }
}
