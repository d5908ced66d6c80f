#pragma once
// Image files: .ppm (binary P6, as the handout says), .png (our banded zlib writer) and .pfm
// (linear float, for error measurement). Writers stream the image in bands straight into a
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

enum class ImageFormat { Ppm, Png, Pfm };

/// The format named by the path's extension (case-insensitive), if we write it.
std::optional<ImageFormat> image_format_for(const std::string& path);

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

/// Calibrates (8-bit formats) and encodes into `sink`; returns false when cancelled.
bool encode_image(const Framebuffer& fb, ImageFormat format, Calibration how, const ByteSink& sink,
                  const WriteOptions& options = {});

/// Calibrates and writes; throws RenderError (with the path and the reason) on failure.
/// Returns false, with no file and no temporary left, when options.cancel was set.
bool write_image(const std::string& path, const Framebuffer& fb, Calibration how, const WriteOptions& options = {});

/// Writes `text` to `path` the way images are written: a temporary file in the same folder,
/// renamed into place once complete; on failure, no file and a RenderError naming the path.
void write_text_file(const std::string& path, std::string_view text);

/// Reads a PPM (P6, 8-bit), PFM or PNG back into [0, 1] floats; throws RenderError.
Framebuffer read_image(const std::string& path);

}  // namespace streamrt
