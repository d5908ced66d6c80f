#pragma once
// sRGB decoding (IEC 61966-2-1), for the colour data that files store encoded: texels and
// the vertex colours of meshes. Its inverse for output, srgb_oetf, is in image/display.h.
#include <array>
#include <cmath>
#include <cstdint>

namespace streamrt {

/// The sRGB EOTF for c in [0, 1] (in double): c / 12.92 up to 0.04045, ((c + 0.055) / 1.055)^2.4
/// above. Shading works in linear light.
inline double srgb_eotf(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

/// The linear value of an 8-bit sRGB code, srgb_eotf(code / 255), from a table.
inline float srgb_to_linear(std::uint8_t code) {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[std::size_t(i)] = float(srgb_eotf(i / 255.0));
        return t;
    }();
    return table[code];
}

}  // namespace streamrt
