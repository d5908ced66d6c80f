#pragma once
// A linear RGB image, the average of each pixel's samples, before calibration.
#include <cstddef>
#include <memory>
#include <vector>

#include "core/default_init.h"

namespace streamrt {

struct Framebuffer {
    int width = 0, height = 0;
    LargeFillLaterVec<float> rgb;  ///< 3 floats per pixel, row-major from the top-left

    Framebuffer() = default;
    /// Zero-filled.
    Framebuffer(int w, int h) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3, 0.f) {}
    /// Uninitialised: for renderers and readers that write every pixel.
    static Framebuffer uninitialized(int w, int h) {
        Framebuffer fb;
        fb.width = w;
        fb.height = h;
        fb.rgb.resize(std::size_t(w) * std::size_t(h) * 3);
        return fb;
    }
    float* pixel(int x, int y) { return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3]; }
    const float* pixel(int x, int y) const {
        return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
    }
};

}  // namespace streamrt
