// PPM (binary P6, the handout's format): 8-bit, display-encoded, written 4 MiB at a time.
#include <algorithm>
#include <vector>

#include "core/default_init.h"
#include "image/format_util.h"
#include "image/image_format.h"

namespace streamrt {

namespace {

using namespace image_detail;

constexpr std::size_t kPpmChunkBytes = std::size_t(4) << 20;  // one write() per 4 MiB

std::size_t ppm_chunk_rows(int width) {
    return std::max<std::size_t>(1, kPpmChunkBytes / (std::size_t(width) * 3));
}

bool encode_ppm(const Framebuffer& fb, const Display& display, const ByteSink& sink, const WriteOptions& o) {
    const EightBitRows to_bytes(fb, display, o.par);
    const std::string header = netpbm_header("P6", fb, "255");
    const std::size_t stride = std::size_t(fb.width) * 3, chunk = ppm_chunk_rows(fb.width);
    LargeFillLaterVec<unsigned char> buf(std::min(chunk, std::size_t(fb.height)) * stride);  // every byte written
    for (std::size_t y0 = 0; y0 < std::size_t(fb.height); y0 += chunk) {
        if (o.cancel && o.cancel->load()) throw Cancelled{};
        const std::size_t rows = std::min(chunk, std::size_t(fb.height) - y0);
        for_each(o.par, rows, 16, [&](std::size_t r) { to_bytes(int(y0 + r), &buf[r * stride]); });
        iovec pieces[2] = {{const_cast<char*>(header.data()), header.size()}, {buf.data(), rows * stride}};
        if (y0 == 0) sink(pieces);
        else sink(std::span<const iovec>(pieces + 1, 1));
    }
    return true;
}

Framebuffer read_ppm(const std::string& path) {
    const std::string data = read_all(path);
    const NetpbmHeader h = read_netpbm_header(data, path);
    Framebuffer fb = Framebuffer::uninitialized(h.width, h.height);
    const std::size_t n = fb.rgb.size();
    if (h.magic != "P6" || h.third != "255" || data.size() < h.raster + n) throw RenderError(path + ": not a P6 PPM");
    for (std::size_t i = 0; i < n; ++i) fb.rgb[i] = static_cast<unsigned char>(data[h.raster + i]) / 255.f;
    return fb;
}

double ppm_buffer_bytes(int width, int height) {
    return double(std::min(ppm_chunk_rows(width), std::size_t(height))) * double(width) * 3;
}

}  // namespace

extern const ImageFormat kPpmFormat{"PPM", ".ppm", true, &encode_ppm, nullptr, &read_ppm, &ppm_buffer_bytes};

}  // namespace streamrt
