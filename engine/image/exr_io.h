#pragma once
// OpenEXR files: RGB scanline images, ZIPS-compressed (deflate per scanline), half or float, holding the
// framebuffer's linear values. OpenEXR itself is in a module loaded on first use (exr_codec.h):
// only engine/modules/exr_codec.cpp includes its headers.
#include <string>

#include "image/framebuffer.h"
#include "image/image_format.h"

namespace streamrt {

/// Writes `fb` to the open file `fd` (named `path` in messages), a band of rows at a time,
/// looking at options.cancel between bands: false when cancelled. Write errors come out as
/// std::system_error (errno), OpenEXR's own as RenderError naming `path`.
bool write_exr(int fd, const std::string& path, const Framebuffer& fb, ExrPixels pixels, const WriteOptions& options);

/// The R, G and B channels of an EXR file (of any pixel type; a missing channel reads 0).
Framebuffer read_exr(const std::string& path);

/// Bytes the EXR writer holds besides the framebuffer (OpenEXR's line buffer and its
/// compression buffers, the line offset table).
double exr_write_buffer_bytes(int width, int height);

}  // namespace streamrt
