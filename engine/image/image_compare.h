#pragma once
// How far two pictures are apart, on linear values (framebuffers, PFM or EXR files) clamped to
// [0, 1]: never on display-encoded (sRGB) 8-bit values.
#include "image/framebuffer.h"

namespace streamrt {

struct ImageDifference {
    double max_abs = 0;       ///< largest |a - b| over every pixel component
    double rmse = 0;          ///< root mean square over every component
    double psnr = 0;          ///< 10 log10(1 / mse) in dB; +inf for identical images
    double share_over = 0;    ///< share of pixels with some component off by more than 1/255
    double rel_mse = 0;       ///< mean of (a - b)^2 / (b^2 + 1e-2), b the reference
    std::size_t pixels = 0;
};

/// Compares `image` with `reference` (same size) after clamping both to [0, 1].
ImageDifference compare_images(const Framebuffer& image, const Framebuffer& reference);

}  // namespace streamrt
