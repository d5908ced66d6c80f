// PNG: 8-bit RGB, display-encoded; our banded writer over zlib (docs/architecture.md, "Writing
// the image"), read back with stb_image.
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <span>
#include <vector>

#include "core/default_init.h"
#include "image/format_util.h"
#include "image/image_format.h"
#include "image/image_io.h"

// One of the two translation units that include stb_image (the other reads textures).
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb_image.h>

namespace streamrt {

namespace {

using namespace image_detail;

constexpr std::size_t kPngBandBytes = std::size_t(128) << 10;
constexpr std::size_t kPngBandsInFlight = 16;  // encoded together, then written in order
// deflate's state for windowBits 15, memLevel 8 (zlib's zconf.h), plus its own bookkeeping.
constexpr double kDeflateStateBytes = (1 << 17) + (1 << 17) + 8192;

void put_be32(unsigned char* p, std::uint32_t v) {
    p[0] = static_cast<unsigned char>(v >> 24);
    p[1] = static_cast<unsigned char>(v >> 16);
    p[2] = static_cast<unsigned char>(v >> 8);
    p[3] = static_cast<unsigned char>(v);
}

// A PNG chunk's framing around data given in pieces: length and type before, CRC after.
struct ChunkFrame {
    unsigned char head[8], crc[4];
    ChunkFrame(const char* type, std::initializer_list<std::span<const unsigned char>> data) {
        std::size_t length = 0;
        std::memcpy(head + 4, type, 4);
        uLong c = ::crc32(0, head + 4, 4);
        for (auto d : data) {
            length += d.size();
            c = ::crc32_z(c, d.data(), d.size());
        }
        put_be32(head, std::uint32_t(length));
        put_be32(crc, std::uint32_t(c));
    }
};

// One band of rows, filtered and deflated as a raw piece of the image's one zlib stream:
// the last band finishes the stream, the others end on a sync flush (byte-aligned, not
// final), so the pieces are independent and simply concatenate.
struct PngBand {
    FillLaterVec<unsigned char> z;  // deflate writes what is kept
    uLong adler = 1;
    std::size_t raw_bytes = 0;
};

void encode_png_band(const Framebuffer& fb, const EightBitRows& to_bytes, int y0, int y1, const PngOptions& o,
                     PngBand& band) {
    const std::size_t stride = std::size_t(fb.width) * 3;
    FillLaterVec<unsigned char> rows(2 * stride), filtered(std::size_t(y1 - y0) * (stride + 1));  // written in full
    unsigned char *prev = rows.data(), *cur = rows.data() + stride;
    // Up reads the row above, also across the band's top edge (it is in the framebuffer).
    if (y0 > 0 && o.filter == PngFilter::Up) to_bytes(y0 - 1, prev);
    else std::fill_n(prev, stride, 0);
    unsigned char* out = filtered.data();
    for (int y = y0; y < y1; ++y) {
        to_bytes(y, cur);
        *out++ = static_cast<unsigned char>(o.filter);
        if (o.filter == PngFilter::Up)
            for (std::size_t i = 0; i < stride; ++i) out[i] = static_cast<unsigned char>(cur[i] - prev[i]);
        else if (o.filter == PngFilter::Sub) {
            std::copy_n(cur, 3, out);
            for (std::size_t i = 3; i < stride; ++i) out[i] = static_cast<unsigned char>(cur[i] - cur[i - 3]);
        } else
            std::copy_n(cur, stride, out);
        out += stride;
        std::swap(prev, cur);
    }
    band.raw_bytes = filtered.size();
    band.adler = ::adler32_z(1, filtered.data(), filtered.size());
    z_stream z{};
    if (deflateInit2(&z, o.level, Z_DEFLATED, -15, 8, o.strategy) != Z_OK) throw std::bad_alloc();
    const bool last = y1 == fb.height;
    band.z.resize(deflateBound(&z, uLong(filtered.size())) + 16);  // + the sync flush's empty block
    z.next_in = filtered.data();
    z.avail_in = uInt(filtered.size());
    z.next_out = band.z.data();
    z.avail_out = uInt(band.z.size());
    const int rc = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
    const bool done = last ? rc == Z_STREAM_END : rc == Z_OK && z.avail_in == 0 && z.avail_out > 0;
    band.z.resize(band.z.size() - z.avail_out);
    deflateEnd(&z);
    if (!done) throw RenderError("PNG encoding failed (zlib " + std::to_string(rc) + ")");
}

bool encode_png(const Framebuffer& fb, const Display& display, const ByteSink& sink, const WriteOptions& o) {
    const EightBitRows to_bytes(fb, display, o.par);
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char ihdr[13];
    put_be32(ihdr, std::uint32_t(fb.width));
    put_be32(ihdr + 4, std::uint32_t(fb.height));
    const unsigned char rest[5] = {8, 2, 0, 0, 0};  // 8-bit RGB, deflate, adaptive filters, no interlace
    std::memcpy(ihdr + 8, rest, 5);
    const ChunkFrame ihdr_frame("IHDR", {ihdr});
    static const unsigned char zlib_header[2] = {0x78, 0x01};  // deflate, 32 KiB window, check bits
    std::vector<iovec> pieces = {{const_cast<unsigned char*>(signature), 8},
                                 {const_cast<unsigned char*>(ihdr_frame.head), 8},
                                 {ihdr, 13},
                                 {const_cast<unsigned char*>(ihdr_frame.crc), 4}};
    const int band_rows = png_band_rows(fb.width);
    const std::size_t bands = (std::size_t(fb.height) + std::size_t(band_rows) - 1) / std::size_t(band_rows);
    std::vector<PngBand> group(std::min(bands, kPngBandsInFlight));
    std::vector<ChunkFrame> frames;
    frames.reserve(group.size());
    uLong adler = 1;
    unsigned char adler_be[4];
    for (std::size_t b0 = 0; b0 < bands; b0 += group.size()) {
        if (o.cancel && o.cancel->load()) throw Cancelled{};
        const std::size_t n = std::min(group.size(), bands - b0);
        for_each(o.par, n, 1, [&](std::size_t i) {
            const int y0 = int(b0 + i) * band_rows;
            encode_png_band(fb, to_bytes, y0, std::min(fb.height, y0 + band_rows), o.png, group[i]);
        });
        // One IDAT per band: the first carries the zlib header, the last the Adler-32.
        frames.clear();
        for (std::size_t i = 0; i < n; ++i) {
            const PngBand& band = group[i];
            adler = ::adler32_combine(adler, band.adler, z_off_t(band.raw_bytes));
            const bool first = b0 + i == 0, last = b0 + i + 1 == bands;
            if (last) put_be32(adler_be, std::uint32_t(adler));
            const std::span<const unsigned char> head(zlib_header, first ? 2 : 0), tail(adler_be, last ? 4 : 0);
            frames.emplace_back("IDAT", std::initializer_list<std::span<const unsigned char>>{head, band.z, tail});
            pieces.push_back({frames.back().head, 8});
            if (first) pieces.push_back({const_cast<unsigned char*>(zlib_header), 2});
            pieces.push_back({const_cast<unsigned char*>(band.z.data()), band.z.size()});
            if (last) pieces.push_back({adler_be, 4});
            pieces.push_back({frames.back().crc, 4});
        }
        if (b0 + n == bands) {
            static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
            pieces.push_back({const_cast<unsigned char*>(iend), 12});
        }
        sink(pieces);
        pieces.clear();
    }
    return true;
}

Framebuffer read_png(const std::string& path) {
    int w = 0, h = 0, n = 0;
    unsigned char* px = stbi_load(path.c_str(), &w, &h, &n, 3);
    if (!px) throw RenderError(path + ": cannot decode PNG");
    Framebuffer fb = Framebuffer::uninitialized(w, h);
    for (std::size_t i = 0; i < fb.rgb.size(); ++i) fb.rgb[i] = px[i] / 255.f;
    stbi_image_free(px);
    return fb;
}

// Each band in flight holds two 8-bit rows, its filtered rows, their deflate bound and a
// deflate state; all of them until the group is written.
double png_buffer_bytes(int width, int height) {
    const double stride = double(width) * 3;
    const int band_rows = png_band_rows(width);
    const double filtered = double(std::min(band_rows, height)) * (stride + 1);
    const double band = 2 * stride + filtered + (filtered + std::ceil(filtered / 1000) + 64) + kDeflateStateBytes;
    const std::size_t bands = (std::size_t(height) + std::size_t(band_rows) - 1) / std::size_t(band_rows);
    return double(std::min(kPngBandsInFlight, bands)) * band;
}

}  // namespace

int png_band_rows(int width) {
    const std::size_t stride = std::size_t(std::max(width, 1)) * 3;
    return int(std::max<std::size_t>(1, (kPngBandBytes + stride - 1) / stride));
}

extern const ImageFormat kPngFormat{"PNG", ".png", true, &encode_png, nullptr, &read_png, &png_buffer_bytes};

}  // namespace streamrt
