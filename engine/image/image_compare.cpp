#include "image/image_compare.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace streamrt {

ImageDifference compare_images(const Framebuffer& image, const Framebuffer& reference) {
    if (image.width != reference.width || image.height != reference.height)
        throw RenderError("cannot compare images of different sizes");
    ImageDifference d;
    d.pixels = std::size_t(image.width) * std::size_t(image.height);
    const auto clamp01 = [](float v) { return std::isfinite(v) ? std::clamp(double(v), 0.0, 1.0) : 0.0; };
    double sum2 = 0, rel = 0;
    std::size_t over = 0;
    for (std::size_t p = 0; p < d.pixels; ++p) {
        bool off = false;
        for (int c = 0; c < 3; ++c) {
            const double a = clamp01(image.rgb[p * 3 + std::size_t(c)]);
            const double b = clamp01(reference.rgb[p * 3 + std::size_t(c)]);
            const double e = std::fabs(a - b);
            d.max_abs = std::max(d.max_abs, e);
            sum2 += e * e;
            rel += e * e / (b * b + 1e-2);
            off |= e > 1.0 / 255.0;
        }
        over += off;
    }
    const double n = double(d.pixels) * 3.0;
    const double mse = n > 0 ? sum2 / n : 0;
    d.rmse = std::sqrt(mse);
    d.psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
    d.rel_mse = n > 0 ? rel / n : 0;
    d.share_over = d.pixels ? double(over) / double(d.pixels) : 0;
    return d;
}

}  // namespace streamrt
