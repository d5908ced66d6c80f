// Radiance HDR (.hdr, RGBE): linear values in 32 bits a pixel, a shared 8-bit exponent and an
// 8-bit mantissa per channel (relative precision 2^-8 of the brightest channel), read by
// image viewers and HDR tools that read no EXR. Written with the format's run-length coding
// ("new" RLE scanlines, widths 8 to 32767; flat pixels otherwise, as the format requires).
// Negative, NaN and infinite values have no RGBE code: they are written as 0.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "image/format_util.h"
#include "image/image_format.h"

namespace streamrt {

namespace {

using namespace image_detail;

constexpr int kRleMinWidth = 8, kRleMaxWidth = 0x7fff;

// Ward's shared-exponent code: the brightest channel's exponent e (v = m 2^e, m in [0.5, 1))
// and each channel's mantissa c 256 / 2^e, truncated. Below 1e-32 the pixel is black.
void to_rgbe(const float* rgb, unsigned char* out) {
    float c[3];
    for (int k = 0; k < 3; ++k) c[k] = std::isfinite(rgb[k]) && rgb[k] > 0.f ? rgb[k] : 0.f;
    const float v = std::max({c[0], c[1], c[2]});
    if (v < 1e-32f) {
        std::memset(out, 0, 4);
        return;
    }
    int e = 0;
    const float scale = std::frexp(v, &e) * 256.f / v;
    for (int k = 0; k < 3; ++k) out[k] = static_cast<unsigned char>(std::min(255.f, c[k] * scale));
    out[3] = static_cast<unsigned char>(e + 128);
}

// The decoded value is the centre of the code's interval, (c + 0.5) 2^(e - 136), as Radiance
// reads it; code 0 of the exponent is black.
void from_rgbe(const unsigned char* in, float* rgb) {
    if (in[3] == 0) {
        rgb[0] = rgb[1] = rgb[2] = 0.f;
        return;
    }
    const float f = std::ldexp(1.f, int(in[3]) - (128 + 8));
    for (int k = 0; k < 3; ++k) rgb[k] = (float(in[k]) + 0.5f) * f;
}

// One channel of a scanline as runs (count > 128: count - 128 copies of the next byte) and
// literal stretches (count <= 128 bytes follow); a run pays from 3 equal bytes on.
void rle_channel(const unsigned char* v, std::size_t n, std::vector<unsigned char>& out) {
    std::size_t i = 0;
    while (i < n) {
        std::size_t run = 1;
        while (i + run < n && run < 127 && v[i + run] == v[i]) ++run;
        if (run >= 3) {
            out.push_back(static_cast<unsigned char>(128 + run));
            out.push_back(v[i]);
            i += run;
            continue;
        }
        // literals up to the next run of 3 (or 128 bytes)
        std::size_t lit = 0;
        while (i + lit < n && lit < 128 &&
               !(i + lit + 2 < n && v[i + lit] == v[i + lit + 1] && v[i + lit] == v[i + lit + 2]))
            ++lit;
        if (lit == 0) lit = 1;
        out.push_back(static_cast<unsigned char>(lit));
        out.insert(out.end(), v + i, v + i + lit);
        i += lit;
    }
}

bool encode_hdr(const Framebuffer& fb, const Display&, const ByteSink& sink, const WriteOptions& o) {
    const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nSOFTWARE=streamrt\n\n-Y " +
                               std::to_string(fb.height) + " +X " + std::to_string(fb.width) + "\n";
    const iovec head{const_cast<char*>(header.data()), header.size()};
    sink(std::span<const iovec>(&head, 1));
    const std::size_t w = std::size_t(fb.width);
    const bool rle = fb.width >= kRleMinWidth && fb.width <= kRleMaxWidth;
    std::vector<unsigned char> rgbe(w * 4), planes(w), out;
    constexpr int kRowsPerWrite = 64;
    for (int y0 = 0; y0 < fb.height; y0 += kRowsPerWrite) {
        if (o.cancel && o.cancel->load()) throw Cancelled{};
        out.clear();
        for (int y = y0; y < std::min(fb.height, y0 + kRowsPerWrite); ++y) {
            for (std::size_t x = 0; x < w; ++x) to_rgbe(fb.pixel(int(x), y), &rgbe[4 * x]);
            if (!rle) {
                out.insert(out.end(), rgbe.begin(), rgbe.end());
                continue;
            }
            const unsigned char mark[4] = {2, 2, static_cast<unsigned char>(w >> 8), static_cast<unsigned char>(w & 255)};
            out.insert(out.end(), mark, mark + 4);
            for (int k = 0; k < 4; ++k) {
                for (std::size_t x = 0; x < w; ++x) planes[x] = rgbe[4 * x + std::size_t(k)];
                rle_channel(planes.data(), w, out);
            }
        }
        const iovec piece{out.data(), out.size()};
        sink(std::span<const iovec>(&piece, 1));
    }
    return true;
}

Framebuffer read_hdr(const std::string& path) {
    const std::string data = read_all(path);
    const auto bad = [&](const char* what) { return RenderError(path + ": not a Radiance HDR file (" + what + ")"); };
    if (data.rfind("#?", 0) != 0) throw bad("no #? signature");
    // Header lines up to an empty line, then the resolution line.
    std::size_t pos = 0;
    for (;;) {
        const std::size_t end = data.find('\n', pos);
        if (end == std::string::npos) throw bad("header without an end");
        const std::string line = data.substr(pos, end - pos);
        pos = end + 1;
        if (line.empty()) break;
        if (line.rfind("FORMAT=", 0) == 0 && line != "FORMAT=32-bit_rle_rgbe") throw bad("not RGBE");
    }
    const std::size_t end = data.find('\n', pos);
    if (end == std::string::npos) throw bad("no resolution line");
    int h = 0, w = 0;
    char tail = 0;
    if (std::sscanf(data.substr(pos, end - pos).c_str(), "-Y %d +X %d%c", &h, &w, &tail) != 2 || w <= 0 || h <= 0 ||
        w > 1 << 20 || h > 1 << 20)
        throw bad("only '-Y H +X W' orientation");
    pos = end + 1;
    Framebuffer fb = Framebuffer::uninitialized(w, h);
    const std::size_t n = std::size_t(w);
    std::vector<unsigned char> rgbe(n * 4);
    const auto byte = [&]() -> unsigned char {
        if (pos >= data.size()) throw bad("truncated pixels");
        return static_cast<unsigned char>(data[pos++]);
    };
    for (int y = 0; y < h; ++y) {
        const bool rle = w >= kRleMinWidth && w <= kRleMaxWidth && pos + 4 <= data.size() && data[pos] == 2 &&
                         data[pos + 1] == 2 && (static_cast<unsigned char>(data[pos + 2]) << 8 |
                                                static_cast<unsigned char>(data[pos + 3])) == w;
        if (rle) {
            pos += 4;
            for (std::size_t k = 0; k < 4; ++k)
                for (std::size_t x = 0; x < n;) {
                    const unsigned count = byte();
                    if (count > 128) {
                        const std::size_t run = count - 128;
                        if (x + run > n) throw bad("a run past the scanline");
                        const unsigned char v = byte();
                        for (std::size_t r = 0; r < run; ++r) rgbe[4 * (x + r) + k] = v;
                        x += run;
                    } else {
                        if (count == 0 || x + count > n) throw bad("a bad literal count");
                        for (std::size_t r = 0; r < count; ++r) rgbe[4 * (x + r) + k] = byte();
                        x += count;
                    }
                }
        } else {
            for (std::size_t i = 0; i < 4 * n; ++i) rgbe[i] = byte();
        }
        for (std::size_t x = 0; x < n; ++x) from_rgbe(&rgbe[4 * x], fb.pixel(int(x), y));
    }
    return fb;
}

// 64 encoded rows at most (5 bytes a pixel in the worst case of the coding) and one row of codes.
double hdr_buffer_bytes(int width, int height) {
    return double(std::min(64, height)) * double(width) * 5 + double(width) * 5;
}

}  // namespace

extern const ImageFormat kHdrFormat{"Radiance HDR", ".hdr", false, &encode_hdr, nullptr, &read_hdr, &hdr_buffer_bytes};

}  // namespace streamrt
