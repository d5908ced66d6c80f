#pragma once
// Image files: the formats of image/image_format.h's registry (.ppm, binary P6 as the
// handout says; .png, our banded zlib writer; .pfm, linear float for error measurement;
// .exr, linear half or float through OpenEXR; .hdr, Radiance RGBE). The 8-bit formats go
// through the display colour chain (image/display.h). Writers stream the image in bands
// straight into a temporary file in the same folder and rename it (image/atomic_file.h), so a
// failed or killed render never leaves half an image, and writing needs memory for a few
// bands, not a second image.
#include <string>

#include "image/atomic_file.h"
#include "image/display.h"
#include "image/framebuffer.h"
#include "image/image_format.h"

namespace streamrt {

/// Rows of one PNG band (an independent piece of the zlib stream): about 128 KiB of pixels,
/// set by the width alone, so the file's bytes never depend on -j.
int png_band_rows(int width);

/// Bytes the writer holds besides the framebuffer while writing a width x height image
/// (the largest over the formats; driver/limits.cpp adds it to the estimate).
double image_write_buffer_bytes(int width, int height);

/// Converts for display (8-bit formats) and encodes into `sink`; returns false when
/// cancelled. Not for a format that seeks in its file (EXR: write_image writes it).
bool encode_image(const Framebuffer& fb, const ImageFormat& format, const Display& display, const ByteSink& sink,
                  const WriteOptions& options = {});

/// Converts for display (8-bit formats) and writes; throws RenderError (with the path and
/// the reason) on failure. Returns false, with no file and no temporary left, when
/// options.cancel was set.
bool write_image(const std::string& path, const Framebuffer& fb, const Display& display,
                 const WriteOptions& options = {});

/// Reads an image back; throws RenderError. The linear formats (PFM, EXR, HDR) give their
/// linear values; PPM (P6, 8-bit) and PNG give the stored codes / 255, still display-encoded
/// (sRGB unless written with colorspace=linear): compare linear files, not those.
Framebuffer read_image(const std::string& path);

}  // namespace streamrt
