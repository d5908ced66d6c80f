// The display colour chain of the 8-bit outputs (exposure, tone curve, calibration, sRGB,
// rounding) against codes worked out by hand from IEC 61966-2-1, and EXR files read back
// with OpenEXR itself. docs/scene-format.md, "Output and display colour".
#include <doctest/doctest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/image_io.h"
#include "parallel/parallelism.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

fs::path temp_file(const std::string& name) {
    return fs::temp_directory_path() / ("streamrt_display_" + std::to_string(::getpid()) + "_" + name);
}

Framebuffer row_of(const std::vector<float>& values) {
    Framebuffer fb(int(values.size()), 1);
    for (std::size_t i = 0; i < values.size(); ++i) fb.rgb[3 * i] = fb.rgb[3 * i + 1] = fb.rgb[3 * i + 2] = values[i];
    return fb;
}

// The PPM raster of `fb` for `d`: one byte per component.
std::vector<int> ppm_codes(const Framebuffer& fb, const Display& d, int jobs = 1) {
    Parallelism par(jobs);
    WriteOptions o;
    o.par = &par;
    std::string out;
    encode_image(fb, image_format(".ppm"), d, [&](std::span<const iovec> pieces) {
        for (const iovec& v : pieces) out.append(static_cast<const char*>(v.iov_base), v.iov_len);
    }, o);
    const std::size_t header = out.size() - fb.rgb.size();
    std::vector<int> codes;
    for (std::size_t i = header; i < out.size(); ++i) codes.push_back(static_cast<unsigned char>(out[i]));
    return codes;
}

// The red code of each pixel of a row_of() image.
std::vector<int> codes(const std::vector<float>& values, const Display& d) {
    const std::vector<int> all = ppm_codes(row_of(values), d);
    std::vector<int> red;
    for (std::size_t i = 0; i < all.size(); i += 3) red.push_back(all[i]);
    return red;
}

Display with(ColorSpace cs, Tonemap tm = Tonemap::Clamp, float exposure = 1.f, Calibration how = Calibration::Clamp) {
    Display d;
    d.colorspace = cs;
    d.tonemap = tm;
    d.exposure = exposure;
    d.calibration = how;
    return d;
}

// IEC 61966-2-1's encoding, written out here independently of the engine, and the code.
int iec_code(double c) {
    const double e = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
    return int(std::floor(255 * e + 0.5));
}

Imf::FrameBuffer float_slices(std::vector<float>& rgb, int width) {
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb.data() + c), 3 * sizeof(float),
                                       std::size_t(width) * 3 * sizeof(float)));
    return fb;
}

}  // namespace

// Worked by hand: 255 (1.055 c^(1/2.4) - 0.055), rounded.
//   0.5:       0.5^(1/2.4) = 0.749154, 1.055 * 0.749154 - 0.055 = 0.735357, * 255 = 187.52 -> 188
//   0.18:      0.18^(1/2.4) = 0.489457 -> 0.461377 * 255 = 117.65 -> 118
//   0.8:       0.8^(1/2.4) = 0.911214 -> 0.906331 * 255 = 231.11 -> 231
//   0.2158605: the linear value of sRGB 128/255 -> 128
//   0.0031308: the boundary, 12.92 * 0.0031308 = 0.040450 (the curve gives 0.040420 there),
//              * 255 = 10.31 -> 10
//   linear segment: 255 * 12.92 c = 0.5 at c = 1.51766e-4: 1.5e-4 -> 0, 1.53e-4 -> 1;
//              0.001 -> 3.29 -> 3
// (Proven against: the OETF without the 0.055 offset fails here.)
TEST_CASE("display: sRGB codes of known linear values, by hand") {
    const Display srgb = with(ColorSpace::Srgb);
    CHECK(codes({0.f, 1.f, 0.5f, 0.18f, 0.8f, 0.2158605f}, srgb) == std::vector<int>{0, 255, 188, 118, 231, 128});
    CHECK(codes({0.0031308f, 1.5e-4f, 1.53e-4f, 0.001f}, srgb) == std::vector<int>{10, 0, 1, 3});
    // The default Display is sRGB; the handout's linear output is one key away.
    CHECK(codes({0.5f, 0.18f}, Display{}) == std::vector<int>{188, 118});
    CHECK(codes({0.5f, 0.18f}, with(ColorSpace::Linear)) == std::vector<int>{128, 46});
    // Clamped first; NaN and infinities are 0 as in the handout's path.
    const float inf = std::numeric_limits<float>::infinity();
    CHECK(codes({2.f, -1.f, std::nanf(""), inf, -inf}, srgb) == std::vector<int>{255, 0, 0, 0, 0});
}

// The table encoder against the formula for every code: the exact smallest float of each
// code found here by bisection on the formula, and the float just below it, plus a sweep of
// a million floats over [0, 1]. (Proven against: a 2048-step table, which crosses two
// thresholds per step near 0, and the OETF without its offset.)
TEST_CASE("display: the sRGB encoder is the IEC formula rounded, for every code boundary") {
    std::vector<float> probe;
    for (int k = 0; k < 255; ++k) {
        std::uint32_t lo = 0, hi = std::bit_cast<std::uint32_t>(1.f);
        while (hi - lo > 1) {
            const std::uint32_t mid = lo + (hi - lo) / 2;
            (iec_code(std::bit_cast<float>(mid)) > k ? hi : lo) = mid;
        }
        probe.push_back(std::bit_cast<float>(hi));
        probe.push_back(std::bit_cast<float>(hi - 1));
    }
    for (std::uint32_t b = 0; b <= std::bit_cast<std::uint32_t>(1.f); b += 1061) probe.push_back(std::bit_cast<float>(b));
    std::vector<int> want;
    for (const float c : probe) want.push_back(iec_code(c));
    const std::vector<int> got = codes(probe, with(ColorSpace::Srgb));
    REQUIRE(got.size() == want.size());
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < got.size(); ++i)
        if (got[i] != want[i] && wrong++ < 5) CHECK_MESSAGE(got[i] == want[i], "c = ", probe[i]);
    CHECK(wrong == 0);
}

// Reinhard per channel, x / (1 + x): 1 -> 1/2, 3 -> 3/4, 1/4 -> 1/5, 0.18 / 0.82 -> 0.18.
// Linear codes: 127.5 -> 128, 191.25 -> 191, 51; sRGB: 188, and 0.18 -> 118 as above.
// (Proven against: the curve x / (2 + x).)
TEST_CASE("display: Reinhard at known values, per channel") {
    CHECK(codes({1.f, 3.f, 0.25f, 0.f}, with(ColorSpace::Linear, Tonemap::Reinhard)) ==
          std::vector<int>{128, 191, 51, 0});
    CHECK(codes({1.f, 0.18f / 0.82f}, with(ColorSpace::Srgb, Tonemap::Reinhard)) == std::vector<int>{188, 118});
    // Very large, infinite and NaN values: the curve's limit 1 for finite ones, 0 otherwise.
    CHECK(codes({3e38f, std::numeric_limits<float>::infinity(), std::nanf("")},
                with(ColorSpace::Linear, Tonemap::Reinhard)) == std::vector<int>{255, 0, 0});
    // Per channel: (1, 3, 0) -> (128, 191, 0).
    Framebuffer fb(1, 1);
    fb.rgb = {1.f, 3.f, 0.f};
    CHECK(ppm_codes(fb, with(ColorSpace::Linear, Tonemap::Reinhard)) == std::vector<int>{128, 191, 0});
}

// Exposure multiplies first: 0.25 * 2 = 0.5 -> linear 128, sRGB 188; 0.5 * 4 = 2 clamps to
// 255, or through Reinhard 2/3 -> 170. (Proven against: the exposure ignored with the clamp
// curve.)
TEST_CASE("display: exposure before the tone curve") {
    CHECK(codes({0.25f}, with(ColorSpace::Linear, Tonemap::Clamp, 2.f)) == std::vector<int>{128});
    CHECK(codes({0.25f}, with(ColorSpace::Srgb, Tonemap::Clamp, 2.f)) == std::vector<int>{188});
    CHECK(codes({0.5f}, with(ColorSpace::Linear, Tonemap::Clamp, 4.f)) == std::vector<int>{255});
    CHECK(codes({0.5f}, with(ColorSpace::Linear, Tonemap::Reinhard, 4.f)) == std::vector<int>{170});
    CHECK(codes({0.5f}, with(ColorSpace::Srgb, Tonemap::Clamp, 0.5f)) == std::vector<int>{137});  // 0.25: 136.96
}

// Normalize divides by the image's maximum after the tone curve: Reinhard (1, 3) ->
// (1/2, 3/4) -> (2/3, 1) -> linear (170, 255); with the clamp curve the exposure cancels:
// (0.5, 2) * e / (2 e) -> (64, 255) for every e. (Proven against: the maximum taken
// before the curve, which gives (1/2, 3/4) / 3 -> (43, 64).)
TEST_CASE("display: normalize after the tone curve") {
    const Calibration n = Calibration::Normalize;
    CHECK(codes({1.f, 3.f}, with(ColorSpace::Linear, Tonemap::Reinhard, 1.f, n)) == std::vector<int>{170, 255});
    for (const float e : {0.5f, 1.f, 8.f})
        CHECK(codes({0.5f, 2.f}, with(ColorSpace::Linear, Tonemap::Clamp, e, n)) == std::vector<int>{64, 255});
    // sRGB after normalize: 0.5 / 2 = 0.25 -> 137 (255 * (1.055 * 0.25^(1/2.4) - 0.055) = 136.96).
    CHECK(codes({0.5f, 2.f}, with(ColorSpace::Srgb, Tonemap::Clamp, 1.f, n)) == std::vector<int>{137, 255});
    // Reinhard with exposure 3 and normalize: (1/3, 1) * 3 = (1, 3) -> (170, 255) as above.
    CHECK(codes({1.f / 3, 1.f}, with(ColorSpace::Linear, Tonemap::Reinhard, 3.f, n)) == std::vector<int>{170, 255});
}

TEST_CASE("display: the 8-bit bytes are the same at -j1 and -j2 for every setting") {
    Framebuffer fb = Framebuffer::uninitialized(301, 97);
    for (std::size_t i = 0; i < fb.rgb.size(); ++i) fb.rgb[i] = float((i * 7919) % 4001) / 1000.f;
    for (const Tonemap tm : {Tonemap::Clamp, Tonemap::Reinhard})
        for (const Calibration how : {Calibration::Clamp, Calibration::Normalize}) {
            const Display d = with(ColorSpace::Srgb, tm, 1.5f, how);
            CHECK(ppm_codes(fb, d, 1) == ppm_codes(fb, d, 2));
        }
}

// PFM holds the framebuffer whatever the display settings.
TEST_CASE("display: PFM is the linear framebuffer whatever the display settings") {
    Framebuffer fb(2, 2);
    fb.rgb = {0.5f, 2.f, 7.25f, 0.f, 1e-3f, 100.f, 0.18f, 3.f, 0.25f, 1.f, 0.75f, 65504.f};
    const fs::path p = temp_file("any.pfm");
    for (const Display& d : {with(ColorSpace::Srgb, Tonemap::Reinhard, 4.f, Calibration::Normalize),
                             with(ColorSpace::Linear, Tonemap::Clamp, 0.5f)}) {
        write_image(p.string(), fb, d);
        CHECK(read_image(p.string()).rgb == fb.rgb);
    }
    fs::remove(p);
}

// Float EXR holds the framebuffer bit for bit, as OpenEXR reads it; half EXR rounds each
// value to the nearest half: 11 significant bits, so |h - v| <= 2^-11 |v| for normal halves
// (|v| >= 2^-14), and values with at most 11 significant bits exactly. (Proven against: the
// G and B channels swapped in the files, and truncation instead of rounding to half, which
// breaks the 2^-11 bound, e.g. at 1 + 3 * 2^-12.)
TEST_CASE("EXR: half and float round trips, read with OpenEXR") {
    const int w = 1501, h = 70;  // three of the writer's half bands: 256 KiB / (1501 * 6) = 29 rows
    Framebuffer fb = Framebuffer::uninitialized(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                fb.pixel(x, y)[c] = std::ldexp(1.f + float((x * 131 + y * 7 + c * 3) % 1000) / 997.f, (x + y + c) % 20 - 12);
    fb.pixel(0, 0)[0] = 1.f + 3.f / 4096;  // 3/4 of a half step (2^-10) above 1: rounds up
    fb.pixel(1, 0)[1] = 0.5f;
    fb.pixel(2, 0)[2] = 1024.f + 1.f;  // 11 significant bits: exact
    for (const ExrPixels px : {ExrPixels::Float, ExrPixels::Half}) {
        CAPTURE(px == ExrPixels::Half);
        Display d;
        d.exr = px;
        const fs::path p = temp_file("rt.exr");
        REQUIRE(write_image(p.string(), fb, d));
        Imf::InputFile file(p.c_str());
        const Imath::Box2i win = file.header().dataWindow();
        REQUIRE(win.max.x - win.min.x + 1 == w);
        REQUIRE(win.max.y - win.min.y + 1 == h);
        const Imf::PixelType want_type = px == ExrPixels::Half ? Imf::HALF : Imf::FLOAT;
        for (const char* name : {"R", "G", "B"}) {
            REQUIRE(file.header().channels().findChannel(name) != nullptr);
            CHECK(file.header().channels().findChannel(name)->type == want_type);
        }
        std::vector<float> back(std::size_t(w) * h * 3, -1.f);
        file.setFrameBuffer(float_slices(back, w));
        file.readPixels(0, h - 1);
        if (px == ExrPixels::Float) {
            CHECK(std::equal(back.begin(), back.end(), fb.rgb.begin()));
        } else {
            std::size_t off = 0;
            for (std::size_t i = 0; i < back.size(); ++i)
                if (!(std::fabs(back[i] - fb.rgb[i]) <= std::ldexp(std::fabs(fb.rgb[i]), -11))) ++off;
            CHECK(off == 0);
            CHECK(back[0] == 1.f + 1.f / 1024);  // 1 + 3 * 2^-12 rounds up to 1 + 2^-10
            CHECK(back[4] == 0.5f);
            CHECK(back[8] == 1025.f);
        }
        // read_image gives the same linear values.
        const Framebuffer again = read_image(p.string());
        CHECK(std::equal(again.rgb.begin(), again.rgb.end(), back.begin()));
        fs::remove(p);
    }
}

TEST_CASE("EXR: failures and Ctrl-C leave no file, and errors name the path") {
    const Framebuffer fb(8, 8);
    const std::string missing_dir = "/nonexistent-dir/out.exr";
    try {
        write_image(missing_dir, fb, Display{});
        FAIL("no error");
    } catch (const RenderError& e) {
        CHECK(std::string(e.what()).find(missing_dir) != std::string::npos);
    }
    const std::atomic<bool> cancel{true};
    WriteOptions o;
    o.cancel = &cancel;
    const fs::path p = temp_file("cancel.exr");
    CHECK_FALSE(write_image(p.string(), fb, Display{}, o));
    CHECK_FALSE(fs::exists(p));
    for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))
        CHECK(e.path().filename().string().find(p.filename().string() + ".tmp") == std::string::npos);
    // An existing file is replaced whole or not at all; a file that is not EXR is refused.
    const fs::path junk = temp_file("junk.exr");
    std::ofstream(junk) << "not an EXR file";
    try {
        read_image(junk.string());
        FAIL("no error");
    } catch (const RenderError& e) {
        CHECK(std::string(e.what()).find(junk.string() + ": cannot read EXR") == 0);
    }
    fs::remove(junk);
    CHECK_THROWS_AS(encode_image(fb, image_format(".exr"), Display{}, [](std::span<const iovec>) {}), RenderError);
}
