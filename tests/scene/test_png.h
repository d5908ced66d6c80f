#pragma once
// Writes small 8-bit RGB PNG files for the texture tests (zlib for the deflate stream and the
// CRCs), and a PNG header alone for the size checks.
#include <zlib.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace streamrt::test {

inline void put32(std::string& s, std::uint32_t v) {
    for (int k = 3; k >= 0; --k) s += char((v >> (8 * k)) & 0xFF);
}

inline void png_chunk(std::string& out, const char* kind, const std::string& data) {
    put32(out, std::uint32_t(data.size()));
    const std::string body = std::string(kind, 4) + data;
    out += body;
    put32(out, std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
}

inline std::string png_ihdr(std::uint32_t w, std::uint32_t h) {
    std::string d;
    put32(d, w);
    put32(d, h);
    d += std::string("\x08\x02\x00\x00\x00", 5);  // 8 bits, RGB, deflate, no filter, no interlace
    return d;
}

/// rgb: w * h * 3 bytes, rows top to bottom.
inline void write_png(const std::string& path, int w, int h, const std::vector<std::uint8_t>& rgb) {
    std::string raw;
    for (int y = 0; y < h; ++y) {
        raw += '\0';
        raw.append(reinterpret_cast<const char*>(rgb.data()) + std::size_t(y) * std::size_t(w) * 3,
                   std::size_t(w) * 3);
    }
    uLongf n = compressBound(uLong(raw.size()));
    std::string z(n, '\0');
    compress(reinterpret_cast<Bytef*>(z.data()), &n, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()));
    z.resize(n);
    std::string out = "\x89PNG\r\n\x1a\n";
    png_chunk(out, "IHDR", png_ihdr(std::uint32_t(w), std::uint32_t(h)));
    png_chunk(out, "IDAT", z);
    png_chunk(out, "IEND", "");
    std::ofstream(path, std::ios::binary) << out;
}

/// A PNG that declares w x h texels and holds no image data (the size is refused first).
inline void write_png_header_only(const std::string& path, std::uint32_t w, std::uint32_t h) {
    std::string out = "\x89PNG\r\n\x1a\n";
    png_chunk(out, "IHDR", png_ihdr(w, h));
    png_chunk(out, "IEND", "");
    std::ofstream(path, std::ios::binary) << out;
}

/// The 2 x 2 test image: top row red, green; bottom row blue, white (codes 0 and 255, whose
/// linear values are exactly 0 and 1).
inline const std::vector<std::uint8_t> kQuad = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};

}  // namespace streamrt::test
