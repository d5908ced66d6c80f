#pragma once
// A linear RGB image, the average of each pixel's samples, before calibration.
#include <cstddef>
#include <memory>
#include <vector>

namespace streamrt {

/// std::allocator whose value-less construct() leaves the float uninitialised, so that a
/// framebuffer every tile overwrites is not zero-filled first (12 GiB at 32768x32768).
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() = default;
    template <class U>
    DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(static_cast<Args&&>(args)...);
    }
};

struct Framebuffer {
    int width = 0, height = 0;
    std::vector<float, DefaultInitAllocator<float>> rgb;  ///< 3 floats per pixel, row-major from the top-left

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
