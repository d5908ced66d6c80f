// The list of output formats (image/image_format.h): each defined in its own file.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include "image/image_format.h"

namespace streamrt {

extern const ImageFormat kPpmFormat, kPngFormat, kPfmFormat, kExrFormat, kHdrFormat;

namespace {
constexpr const ImageFormat* kFormats[] = {&kPpmFormat, &kPngFormat, &kPfmFormat, &kExrFormat, &kHdrFormat};
}  // namespace

std::span<const ImageFormat* const> image_formats() { return kFormats; }

const ImageFormat* image_format_for(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const ImageFormat* f : kFormats)
        if (f->extension == ext) return f;
    return nullptr;
}

const ImageFormat& image_format(std::string_view extension) {
    for (const ImageFormat* f : kFormats)
        if (f->extension == extension) return *f;
    throw std::invalid_argument("no image format has the extension " + std::string(extension));
}

std::string image_format_extensions() {
    std::string s;
    for (std::size_t i = 0; i < std::size(kFormats); ++i) {
        if (i > 0) s += i + 1 == std::size(kFormats) ? " or " : ", ";
        s += kFormats[i]->extension;
    }
    return s;
}

}  // namespace streamrt
