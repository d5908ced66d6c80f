#pragma once
// Whether two pictures are the same to the bit (determinism and identity tests).
#include <cstring>

#include "image/framebuffer.h"

namespace streamrt {

inline bool bit_identical(const Framebuffer& a, const Framebuffer& b) {
    if (a.width != b.width || a.height != b.height) return false;
    for (int y = 0; y < a.height; ++y)
        if (std::memcmp(a.pixel(0, y), b.pixel(0, y), sizeof(float) * 3 * std::size_t(a.width)) != 0) return false;
    return true;
}

}  // namespace streamrt
