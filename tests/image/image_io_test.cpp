// Image files written and read back; calibration; atomic replacement.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "image/image_compare.h"
#include "image/image_io.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {
Framebuffer gradient(int w, int h) {
    Framebuffer fb(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = fb.pixel(x, y);
            p[0] = float(x) / float(w - 1);
            p[1] = float(y) / float(h - 1);
            p[2] = x == 0 ? 2.f : 0.25f;  // 2.0 clamps to 1 in 8-bit formats
        }
    return fb;
}
fs::path temp_file(const std::string& name) { return fs::temp_directory_path() / ("streamrt_img_" + name); }
}  // namespace

TEST_CASE("PPM, PNG and PFM round-trip") {
    const Framebuffer fb = gradient(7, 5);
    for (const char* ext : {"ppm", "png"}) {
        CAPTURE(ext);
        const fs::path p = temp_file(std::string("rt.") + ext);
        write_image(p, fb, Calibration::Clamp);
        const Framebuffer back = read_image(p);
        REQUIRE(back.width == 7);
        REQUIRE(back.height == 5);
        CHECK(back.pixel(6, 0)[0] == doctest::Approx(1.0));
        CHECK(back.pixel(0, 4)[1] == doctest::Approx(1.0));
        CHECK(back.pixel(0, 0)[2] == doctest::Approx(1.0));          // clamped from 2
        CHECK(back.pixel(3, 2)[2] == doctest::Approx(64 / 255.0));   // 0.25 * 255 rounds to 64
        CHECK(back.pixel(3, 0)[0] == doctest::Approx(128 / 255.0));  // 0.5 -> 128
        fs::remove(p);
    }
    const fs::path p = temp_file("rt.pfm");
    write_image(p, fb, Calibration::Clamp);
    const Framebuffer back = read_image(p);
    CHECK(back.rgb == fb.rgb);  // linear floats, bit for bit, not calibrated
    fs::remove(p);
}

TEST_CASE("PPM header is binary P6 as the handout asks") {
    Framebuffer fb(2, 1);
    fb.rgb = {1, 0, 0, 0, 0.5f, 1};
    const fs::path p = temp_file("hdr.ppm");
    write_image(p, fb, Calibration::Clamp);
    std::ifstream in(p, std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), {});
    CHECK(data == std::string("P6\n2 1\n255\n\xff\x00\x00\x00\x80\xff", 17));
    fs::remove(p);
}

TEST_CASE("calibration: clamp, normalize by the maximum, NaN to 0") {
    Framebuffer fb(2, 1);
    fb.rgb = {0.5f, 4.f, -1.f, 2.f, std::nanf(""), 1.f};
    const Framebuffer c = calibrate(fb, Calibration::Clamp);
    CHECK(std::vector<float>(c.rgb.begin(), c.rgb.end()) == std::vector<float>{0.5f, 1.f, 0.f, 1.f, 0.f, 1.f});
    const Framebuffer n = calibrate(fb, Calibration::Normalize);
    CHECK(std::vector<float>(n.rgb.begin(), n.rgb.end()) == std::vector<float>{0.125f, 1.f, 0.f, 0.5f, 0.f, 0.25f});
}

TEST_CASE("a failed write leaves nothing behind and an existing file untouched") {
    const Framebuffer fb = gradient(3, 3);
    CHECK_THROWS_AS(write_image("/nonexistent-dir/out.png", fb, Calibration::Clamp), RenderError);
    CHECK_THROWS_AS(write_image(temp_file("x.jpg"), fb, Calibration::Clamp), RenderError);
    const fs::path p = temp_file("keep.ppm");
    write_image(p, fb, Calibration::Clamp);
    const auto size = fs::file_size(p);
    write_image(p, gradient(4, 4), Calibration::Clamp);  // replaced whole
    CHECK(fs::file_size(p) > size);
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
        CHECK(e.path().filename().string().find(".keep.ppm.tmp") == std::string::npos);
    fs::remove(p);
}

TEST_CASE("image comparison figures") {
    Framebuffer a(2, 1), b(2, 1);
    a.rgb = {0, 0, 0, 1, 1, 1};
    b.rgb = {0, 0, 0.1f, 1, 1, 1};
    const ImageDifference d = compare_images(a, b);
    CHECK(d.max_abs == doctest::Approx(0.1));
    CHECK(d.rmse == doctest::Approx(std::sqrt(0.01 / 6)));
    CHECK(d.psnr == doctest::Approx(10 * std::log10(600.0)));
    CHECK(d.share_over == doctest::Approx(0.5));
    CHECK(std::isinf(compare_images(a, a).psnr));
}
