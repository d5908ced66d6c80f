#pragma once
// Image files: .ppm (binary P6, as the handout says), .png (our banded zlib writer), .pfm
// (linear float, for error measurement) and .exr (linear half or float, OpenEXR; for
// compositing and denoising tools). The 8-bit formats go through the display colour chain
// (Display below; docs/scene-format.md, "Output and display colour"). Writers stream the image in bands straight into a
// temporary file in the same folder and rename it, so a failed or killed render never
// leaves half an image, and writing needs memory for a few bands, not a second image.
#include <sys/uio.h>

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "image/framebuffer.h"
#include "scene/scene.h"

namespace streamrt {

class Parallelism;

enum class ImageFormat { Ppm, Png, Pfm, Exr };

/// The format named by the path's extension (case-insensitive), if we write it.
std::optional<ImageFormat> image_format_for(const std::string& path);

/// How the linear framebuffer becomes 8-bit values (PNG, PPM), in this order:
///   x = v * exposure -> tone curve T(x) (clamp: none; reinhard: x / (1 + x) per channel, x >= 0)
///   -> calibration (clamp: min(T, 1); normalize: T / max over the image of T, the maximum
///      taken after the tone curve) -> sRGB OETF (IEC 61966-2-1, exact piecewise) or linear
///   -> round(255 c). NaN and infinities become 0.
/// With tonemap=clamp and calibration=normalize the exposure cancels out (v * e / max(v * e)).
/// PFM and EXR files hold the framebuffer's linear values untouched.
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

/// The scene's `image` keys that make its Display.
Display display_of(const RenderSettings& s);

/// The sRGB OETF of IEC 61966-2-1 for c in [0, 1] (in double): 12.92 c up to 0.0031308,
/// 1.055 c^(1/2.4) - 0.055 above.
double srgb_oetf(double c);

/// Brings values into [0, 1]: clamp, or divide by the image's maximum (the handout's
/// calibration). NaN becomes 0.
Framebuffer calibrate(const Framebuffer& fb, Calibration how);

/// The PNG writer's knobs (perf/image_bench.cpp measures them; the defaults are the choice).
enum class PngFilter : unsigned char { None = 0, Sub = 1, Up = 2 };
struct PngOptions {
    int level = 1;            ///< zlib level
    int strategy = 3;         ///< zlib strategy (3 = Z_RLE)
    PngFilter filter = PngFilter::Sub;
};

struct WriteOptions {
    Parallelism* par = nullptr;                 ///< encode bands in parallel (else one thread)
    const std::atomic<bool>* cancel = nullptr;  ///< checked between bands: stop, leave nothing
    PngOptions png;
};

/// Rows of one PNG band (an independent piece of the zlib stream): about 128 KiB of pixels,
/// set by the width alone, so the file's bytes never depend on -j.
int png_band_rows(int width);

/// Bytes the writer holds besides the framebuffer while writing a width x height image
/// (the largest of the formats; driver/limits.cpp adds it to the estimate).
double image_write_buffer_bytes(int width, int height);

/// Receives the encoded file in order, a few large pieces at a time.
using ByteSink = std::function<void(std::span<const iovec>)>;

/// Converts for display (8-bit formats) and encodes into `sink`; returns false when
/// cancelled. Not for EXR, whose writer seeks back in its file (write_image writes it).
bool encode_image(const Framebuffer& fb, ImageFormat format, const Display& display, const ByteSink& sink,
                  const WriteOptions& options = {});

/// Converts for display (8-bit formats) and writes; throws RenderError (with the path and
/// the reason) on failure. Returns false, with no file and no temporary left, when
/// options.cancel was set.
bool write_image(const std::string& path, const Framebuffer& fb, const Display& display,
                 const WriteOptions& options = {});

/// Writes `text` to `path` the way images are written: a temporary file in the same folder,
/// renamed into place once complete; on failure, no file and a RenderError naming the path.
void write_text_file(const std::string& path, std::string_view text);

/// Reads an image back; throws RenderError. PFM and EXR give their linear values; PPM (P6,
/// 8-bit) and PNG give the stored codes / 255, still display-encoded (sRGB unless written
/// with colorspace=linear): compare linear PFM or EXR files, not those.
Framebuffer read_image(const std::string& path);

}  // namespace streamrt
