#pragma once
// Image files: .ppm (binary P6, as the handout says), .png (stb_image_write) and .pfm
// (linear float, for error measurement). Writers go through a temporary file in the same
// folder and a rename, so a failed or killed render never leaves half an image.
#include <optional>
#include <string>

#include "image/framebuffer.h"
#include "scene/scene.h"

namespace streamrt {

enum class ImageFormat { Ppm, Png, Pfm };

/// The format named by the path's extension (case-insensitive), if we write it.
std::optional<ImageFormat> image_format_for(const std::string& path);

/// Brings values into [0, 1]: clamp, or divide by the image's maximum (the handout's
/// calibration). NaN becomes 0.
Framebuffer calibrate(const Framebuffer& fb, Calibration how);

/// Calibrates and writes; throws RenderError (with the path and the reason) on failure.
void write_image(const std::string& path, const Framebuffer& fb, Calibration how);

/// Reads a PPM (P6, 8-bit), PFM or PNG back into [0, 1] floats; throws RenderError.
Framebuffer read_image(const std::string& path);

}  // namespace streamrt
