// Image files written and read back; the handout's calibration (raw linear output); atomic
// replacement. The display colour chain and EXR: display_test.cpp.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstdint>
#include <limits>
#include <string>

#include "core/error.h"
#include "image/atomic_file.h"
#include "image/image_compare.h"
#include "image/image_io.h"
#include "parallel/parallelism.h"

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

// Values that probe every branch of the 8-bit conversion: both sides of each rounding
// half, the clamps, NaN and both infinities.
Framebuffer awkward(int w, int h) {
    const float probes[] = {0.f, 0.5f / 255, std::nextafter(0.5f / 255, 0.f), 1.5f / 255, 0.5f, 0.25f, 1.f,
                            2.f, -1.f, std::nanf(""), std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(), 254.5f / 255, 0.999f, 1e-8f};
    Framebuffer fb(w, h);
    for (std::size_t i = 0; i < fb.rgb.size(); ++i)
        fb.rgb[i] = i % 7 == 3 ? probes[(i / 7) % std::size(probes)] : float((i * 37 + i / 5) % 256) / 255.f;
    return fb;
}

// What the writers must store: lround(calibrated * 255), the handout's rounding.
std::vector<unsigned char> expected_bytes(const Framebuffer& fb, Calibration how) {
    const Framebuffer c = calibrate(fb, how);
    std::vector<unsigned char> b(c.rgb.size());
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<unsigned char>(std::lround(c.rgb[i] * 255.f));
    return b;
}

std::vector<unsigned char> as_bytes(const Framebuffer& fb) {
    std::vector<unsigned char> b(fb.rgb.size());
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<unsigned char>(std::lround(fb.rgb[i] * 255.f));
    return b;
}

std::string file_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), {});
}

std::string encoded(const Framebuffer& fb, const ImageFormat& format, Calibration how, int jobs) {
    Parallelism par(jobs);
    WriteOptions o;
    o.par = &par;
    std::string out;
    encode_image(fb, format, Display::raw(how), [&](std::span<const iovec> pieces) {
        for (const iovec& v : pieces) out.append(static_cast<const char*>(v.iov_base), v.iov_len);
    }, o);
    return out;
}
}  // namespace

TEST_CASE("PPM, PNG and PFM round-trip") {
    const Framebuffer fb = gradient(7, 5);
    for (const char* ext : {"ppm", "png"}) {
        CAPTURE(ext);
        const fs::path p = temp_file(std::string("rt.") + ext);
        write_image(p, fb, Display::raw(Calibration::Clamp));
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
    write_image(p, fb, Display::raw(Calibration::Clamp));
    const Framebuffer back = read_image(p);
    CHECK(back.rgb == fb.rgb);  // linear floats, bit for bit, not calibrated
    fs::remove(p);
}

TEST_CASE("PPM header is binary P6 as the handout asks") {
    Framebuffer fb(2, 1);
    fb.rgb = {1, 0, 0, 0, 0.5f, 1};
    const fs::path p = temp_file("hdr.ppm");
    write_image(p, fb, Display::raw(Calibration::Clamp));
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
    CHECK_THROWS_AS(write_image("/nonexistent-dir/out.png", fb, Display::raw(Calibration::Clamp)), RenderError);
    CHECK_THROWS_AS(write_image(temp_file("x.jpg"), fb, Display::raw(Calibration::Clamp)), RenderError);
    const fs::path p = temp_file("keep.ppm");
    write_image(p, fb, Display::raw(Calibration::Clamp));
    const auto size = fs::file_size(p);
    write_image(p, gradient(4, 4), Display::raw(Calibration::Clamp));  // replaced whole
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

TEST_CASE("PNG: read back by stb_image, the exact 8-bit values, at every band layout") {
    // 1x1; odd widths; one row short of, exactly, and one past a band; many bands.
    const int rows_43 = png_band_rows(43);
    CHECK(rows_43 == 1017);  // 128 KiB of 43 * 3-byte rows, rounded up
    CHECK(png_band_rows(2560) == 18);
    CHECK(png_band_rows(32768) == 2);
    const std::pair<int, int> sizes[] = {{1, 1}, {7, 5}, {43, rows_43 - 1}, {43, rows_43}, {43, rows_43 + 1},
                                         {2561, 3 * png_band_rows(2561) + 5}};
    for (const Calibration how : {Calibration::Clamp, Calibration::Normalize})
        for (const auto& [w, h] : sizes) {
            CAPTURE(w);
            CAPTURE(h);
            const Framebuffer fb = awkward(w, h);
            const fs::path p = temp_file("bands.png");
            write_image(p, fb, Display::raw(how));
            const Framebuffer back = read_image(p);
            REQUIRE(back.width == w);
            REQUIRE(back.height == h);
            CHECK(as_bytes(back) == expected_bytes(fb, how));
            fs::remove(p);
        }
}

TEST_CASE("PPM: the fused calibration stores lround(calibrated * 255) exactly") {
    for (const Calibration how : {Calibration::Clamp, Calibration::Normalize}) {
        const Framebuffer fb = awkward(33, 17);
        const std::string ppm = encoded(fb, image_format(".ppm"), how, 2);
        const std::string header = "P6\n33 17\n255\n";
        REQUIRE(ppm.size() == header.size() + 33 * 17 * 3);
        CHECK(ppm.substr(0, header.size()) == header);
        const auto want = expected_bytes(fb, how);
        CHECK(ppm.substr(header.size()) == std::string(want.begin(), want.end()));
    }
}

TEST_CASE("PPM and PFM larger than one write chunk keep every row in place") {
    // 4 MiB chunks: 1400 rows of 1000 pixels are two chunks (1398 + 2 rows).
    Framebuffer fb = Framebuffer::uninitialized(1000, 1400);
    for (std::size_t i = 0; i < fb.rgb.size(); ++i) fb.rgb[i] = float(i % 251) / 250.f;
    for (const char* ext : {"ppm", "pfm"}) {
        CAPTURE(ext);
        const fs::path p = temp_file(std::string("chunks.") + ext);
        write_image(p, fb, Display::raw(Calibration::Clamp));
        const Framebuffer back = read_image(p);
        REQUIRE(back.rgb.size() == fb.rgb.size());
        if (std::string(ext) == "pfm") CHECK(back.rgb == fb.rgb);
        else CHECK(as_bytes(back) == expected_bytes(fb, Calibration::Clamp));
        fs::remove(p);
    }
}

TEST_CASE("blocks allocated ahead of the writes: the file's size stays its bytes, nothing beyond its end") {
    const fs::path p = temp_file("ahead.bin");
    {
        const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        REQUIRE(fd >= 0);
        allocate_ahead(fd, 0, 1 << 20);
        struct stat st {};
        REQUIRE(::fstat(fd, &st) == 0);
        CHECK(st.st_size == 0);  // the size is the bytes written, none yet
        if (st.st_blocks == 0) MESSAGE("this file system does not allocate ahead (fallocate)");
        else CHECK(std::uint64_t(st.st_blocks) * 512 >= (1u << 20));
        ::close(fd);
    }
    // A PPM of two write chunks over a larger file: its own size, its own bytes, and no
    // blocks left allocated past its end.
    const Framebuffer big = gradient(1200, 1400), fb = gradient(1000, 1400);
    const fs::path ppm = temp_file("ahead.ppm");
    write_image(ppm, big, Display::raw(Calibration::Clamp));
    write_image(ppm, fb, Display::raw(Calibration::Clamp));
    const std::uint64_t size = std::string("P6\n1000 1400\n255\n").size() + 1000ull * 1400 * 3;
    CHECK(fs::file_size(ppm) == size);
    CHECK(as_bytes(read_image(ppm)) == expected_bytes(fb, Calibration::Clamp));
    struct stat st {};
    REQUIRE(::stat(ppm.c_str(), &st) == 0);
    CHECK(std::uint64_t(st.st_blocks) * 512 <= (size + 4095) / 4096 * 4096 + 4096);
    fs::remove(p);
    fs::remove(ppm);
}

TEST_CASE("the file's bytes are the same at -j1 and -j2") {
    const Framebuffer fb = awkward(301, 3 * png_band_rows(301) + 7);
    for (const ImageFormat* f : {&image_format(".png"), &image_format(".ppm"), &image_format(".pfm")}) {
        const std::string one = encoded(fb, *f, Calibration::Clamp, 1);
        CHECK(one.size() > 1000);
        CHECK(one == encoded(fb, *f, Calibration::Clamp, 2));
    }
}

TEST_CASE("a cancelled write leaves neither the image nor a temporary file") {
    const Framebuffer fb = gradient(64, 64);
    const std::atomic<bool> cancel{true};
    WriteOptions o;
    o.cancel = &cancel;
    for (const char* ext : {"png", "ppm"}) {
        const fs::path p = temp_file(std::string("cancel.") + ext);
        CHECK_FALSE(write_image(p, fb, Display::raw(Calibration::Clamp), o));
        CHECK_FALSE(fs::exists(p));
        for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
            CHECK(e.path().filename().string().find(".streamrt_img_cancel.") == std::string::npos);
    }
}

TEST_CASE("the write buffers are a few bands, not a copy of the image") {
    // 2560x1440: 16 PNG bands of 18 rows in flight, each two 8-bit rows, the filtered rows,
    // their deflate bound and a deflate state.
    const double filtered = 18.0 * 7681;
    CHECK(image_write_buffer_bytes(2560, 1440) == 16 * (2 * 7680 + filtered + filtered + 139 + 64 + 270336));
    CHECK(image_write_buffer_bytes(32768, 32768) < 14e6);
}
