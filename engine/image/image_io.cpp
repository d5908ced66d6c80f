#include "image/image_io.h"

#include <algorithm>
#include <cstdint>

#include "core/error.h"
#include "image/format_util.h"

namespace streamrt {

double image_write_buffer_bytes(int width, int height) {
    double most = 0;
    for (const ImageFormat* f : image_formats()) most = std::max(most, f->buffer_bytes(width, height));
    return most;
}

bool encode_image(const Framebuffer& fb, const ImageFormat& format, const Display& display, const ByteSink& sink,
                  const WriteOptions& options) {
    if (fb.width <= 0 || fb.height <= 0) throw RenderError("cannot encode an empty image");
    if (!format.encode) throw RenderError(std::string(format.name) + " is written to files only (write_image)");
    try {
        return format.encode(fb, display, sink, options);
    } catch (const image_detail::Cancelled&) {
        return false;
    }
}

bool write_image(const std::string& path, const Framebuffer& fb, const Display& display,
                 const WriteOptions& options) {
    const ImageFormat* format = image_format_for(path);
    if (!format) throw RenderError(path + ": unknown image format (expected " + image_format_extensions() + ")");
    if (fb.width <= 0 || fb.height <= 0) throw RenderError("cannot encode an empty image");
    return write_atomically(path, options.cancel, [&](int fd) {
        if (format->write_file) return format->write_file(fd, path, fb, display, options);
        std::uint64_t at = 0;  // bytes written so far
        return encode_image(
            fb, *format, display,
            [fd, &at](std::span<const iovec> pieces) {
                std::uint64_t n = 0;
                for (const iovec& v : pieces) n += v.iov_len;
                allocate_ahead(fd, at, n);
                write_all(fd, pieces);
                at += n;
            },
            options);
    });
}

Framebuffer read_image(const std::string& path) {
    const ImageFormat* format = image_format_for(path);
    if (!format) throw RenderError(path + ": unknown image format (expected " + image_format_extensions() + ")");
    return format->read(path);
}

}  // namespace streamrt
