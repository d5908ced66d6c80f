// PFM: the framebuffer's linear float values, for error measurement.
#include <cstring>
#include <vector>

#include "image/format_util.h"
#include "image/image_format.h"

namespace streamrt {

namespace {

using namespace image_detail;

// PFM rows go bottom to top: handed to the sink straight from the framebuffer, no copy.
bool encode_pfm(const Framebuffer& fb, const Display&, const ByteSink& sink, const WriteOptions&) {
    const std::string header = netpbm_header("PF", fb, "-1.0");  // negative: little-endian
    std::vector<iovec> pieces;
    pieces.reserve(std::size_t(fb.height) + 1);
    pieces.push_back({const_cast<char*>(header.data()), header.size()});
    for (int y = fb.height - 1; y >= 0; --y)
        pieces.push_back({const_cast<float*>(fb.pixel(0, y)), std::size_t(fb.width) * 3 * sizeof(float)});
    sink(pieces);
    return true;
}

Framebuffer read_pfm(const std::string& path) {
    const std::string data = read_all(path);
    const NetpbmHeader h = read_netpbm_header(data, path);  // third word: the scale, negative (little-endian)
    const int w = h.width;
    Framebuffer fb = Framebuffer::uninitialized(w, h.height);
    if (h.magic != "PF" || data.size() < h.raster + fb.rgb.size() * sizeof(float)) throw RenderError(path + ": not an RGB PFM");
    for (int y = 0; y < h.height; ++y)
        std::memcpy(fb.pixel(0, h.height - 1 - y), data.data() + h.raster + std::size_t(y) * w * 3 * sizeof(float),
                    std::size_t(w) * 3 * sizeof(float));
    return fb;
}

// The header and one pointer per row (writev), no copy of the pixels.
double pfm_buffer_bytes(int, int height) { return (double(height) + 1) * sizeof(iovec); }

}  // namespace

extern const ImageFormat kPfmFormat{"PFM", ".pfm", false, &encode_pfm, nullptr, &read_pfm, &pfm_buffer_bytes};

}  // namespace streamrt
