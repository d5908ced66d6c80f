#pragma once
// The display colour chain of the 8-bit formats (docs/scene-format.md, "Output and display
// colour"): how the linear framebuffer becomes the bytes of a PNG or PPM, one row at a time,
// with no converted copy of the image.
#include "image/framebuffer.h"
#include "image/display_settings.h"

namespace streamrt {

class Parallelism;

/// The sRGB OETF of IEC 61966-2-1 for c in [0, 1] (in double): 12.92 c up to 0.0031308,
/// 1.055 c^(1/2.4) - 0.055 above.
double srgb_oetf(double c);  // its inverse, srgb_eotf, is in core/srgb.h

/// Brings values into [0, 1]: clamp, or divide by the image's maximum (the handout's
/// calibration). NaN becomes 0.
Framebuffer calibrate(const Framebuffer& fb, Calibration how);

struct SrgbTables;

/// The 8-bit rows of one image for one Display, its factors found once (the normalize
/// maximum's pass included, on `par`'s threads when given). Linear, clamp, exposure 1 is the
/// handout's conversion. Calling it is thread-safe.
class EightBitRows {
  public:
    EightBitRows(const Framebuffer& fb, const Display& d, Parallelism* par);
    /// Row y as fb.width * 3 bytes.
    void operator()(int y, unsigned char* out) const;

  private:
    using Row = void (*)(const Framebuffer&, int, float, float, const SrgbTables*, unsigned char*);  // tables: sRGB rows only
    const Framebuffer& fb_;
    float pre_ = 1.f, post_ = 1.f;
    Row row_ = nullptr;
    const SrgbTables* tables_ = nullptr;
};

}  // namespace streamrt
