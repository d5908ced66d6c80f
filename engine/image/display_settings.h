#pragma once
// The settings of the display colour chain (docs/scene-format.md, "Output and display colour"):
// plain values and their names, with no dependency on the scene, so the scene's `image` keys,
// the command line and the image writers share one definition.
#include <cstdint>

#include "core/enum_names.h"

namespace streamrt {

enum class Calibration : std::uint8_t { Clamp, Normalize };
inline constexpr EnumName<Calibration> kCalibrationNames[] = {{Calibration::Clamp, "clamp"},
                                                              {Calibration::Normalize, "normalize"}};
enum class ColorSpace : std::uint8_t { Srgb, Linear };
inline constexpr EnumName<ColorSpace> kColorSpaceNames[] = {{ColorSpace::Srgb, "srgb"}, {ColorSpace::Linear, "linear"}};
enum class Tonemap : std::uint8_t { Clamp, Reinhard };
inline constexpr EnumName<Tonemap> kTonemapNames[] = {{Tonemap::Clamp, "clamp"}, {Tonemap::Reinhard, "reinhard"}};
enum class ExrPixels : std::uint8_t { Half, Float };
inline constexpr EnumName<ExrPixels> kExrPixelsNames[] = {{ExrPixels::Half, "half"}, {ExrPixels::Float, "float"}};

/// How the linear framebuffer becomes 8-bit values (PNG, PPM), in this order:
///   x = v * exposure -> tone curve T(x) (clamp: none; reinhard: x / (1 + x) per channel, x >= 0)
///   -> calibration (clamp: min(T, 1); normalize: T / max over the image of T, the maximum
///      taken after the tone curve) -> sRGB OETF (IEC 61966-2-1, exact piecewise) or linear
///   -> round(255 c). NaN and infinities become 0.
/// With tonemap=clamp and calibration=normalize the exposure cancels out (v * e / max(v * e)).
/// The linear formats (PFM, EXR, HDR) hold the framebuffer's values untouched.
struct Display {
    Calibration calibration = Calibration::Clamp;
    ColorSpace colorspace = ColorSpace::Srgb;
    Tonemap tonemap = Tonemap::Clamp;
    float exposure = 1.f;
    ExrPixels exr = ExrPixels::Half;

    /// The handout's output: clamped or normalised values stored linearly, no tone curve.
    static Display raw(Calibration how) {
        Display d;
        d.calibration = how;
        d.colorspace = ColorSpace::Linear;
        return d;
    }
};

}  // namespace streamrt
