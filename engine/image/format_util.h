#pragma once
// Helpers the format files share (image/*_format.cpp): not part of the image API.
#include <cctype>
#include <cstddef>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "image/framebuffer.h"
#include "parallel/parallelism.h"

namespace streamrt::image_detail {

/// Thrown by an encoder that saw the cancel flag; encode_image turns it into `false`.
struct Cancelled {};

/// Runs body(i) for i in [0, n), on the writer's threads when it has any.
template <class Body>
void for_each(Parallelism* par, std::size_t n, std::size_t grain, Body&& body) {
    if (par) par->for_each_index(n, grain, body);
    else
        for (std::size_t i = 0; i < n; ++i) body(i);
}

/// The whole file, for the readers; RenderError if it cannot be opened.
inline std::string read_all(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw RenderError(path + ": cannot open");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Whitespace-separated header tokens with '#' comments (the P6 and PF headers).
struct HeaderReader {
    const std::string& data;
    std::size_t pos = 0;
    std::string token() {
        while (pos < data.size()) {
            if (data[pos] == '#') {
                while (pos < data.size() && data[pos] != '\n') ++pos;
            } else if (std::isspace(static_cast<unsigned char>(data[pos]))) {
                ++pos;
            } else {
                break;
            }
        }
        const std::size_t start = pos;
        while (pos < data.size() && !std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
        return data.substr(start, pos - start);
    }
};

/// A P6 or PF header read: its three words, the size, and where the raster starts (after
/// the single whitespace byte that ends the header). RenderError for a size that is not positive.
struct NetpbmHeader {
    std::string magic, third;
    int width = 0, height = 0;
    std::size_t raster = 0;
};
inline NetpbmHeader read_netpbm_header(const std::string& data, const std::string& path) {
    HeaderReader r{data};
    NetpbmHeader h;
    h.magic = r.token();
    h.width = std::atoi(r.token().c_str());
    h.height = std::atoi(r.token().c_str());
    h.third = r.token();
    h.raster = r.pos + 1;
    if (h.width <= 0 || h.height <= 0) throw RenderError(path + ": bad header");
    return h;
}

/// "MAGIC\nW H\nTHIRD\n": the P6 and PF headers.
inline std::string netpbm_header(const char* magic, const Framebuffer& fb, const char* third) {
    return std::string(magic) + "\n" + std::to_string(fb.width) + " " + std::to_string(fb.height) + "\n" + third +
           "\n";
}

}  // namespace streamrt::image_detail
