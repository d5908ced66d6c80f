#pragma once
// The output formats' registry: everything streamrt knows of a format (its extension, how it
// is encoded and read back, whether it goes through the display colour chain, the memory its
// writer holds) is one `ImageFormat` record, defined in the format's own file
// (image/<name>_format.cpp) and listed once in image/image_formats.cpp. The writer, the
// reader, the memory estimate and every message that names the formats read the list.
//
// Adding a format: its file, defining `const ImageFormat k<Name>Format`, and its name in the
// list of image/image_formats.cpp (docs/architecture.md, "Writing the image").
#include <sys/uio.h>

#include <atomic>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "image/display.h"
#include "image/framebuffer.h"

namespace streamrt {

class Parallelism;

/// The PNG writer's knobs. The product always writes with the defaults (the measured choice,
/// docs/performance.md "Image output"); the fields stay settable because perf/image_bench.cpp
/// sets all three to measure the alternatives against them.
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

/// Receives the encoded file in order, a few large pieces at a time.
using ByteSink = std::function<void(std::span<const iovec>)>;

/// One output format.
struct ImageFormat {
    std::string_view name;       ///< "PNG", for messages
    std::string_view extension;  ///< ".png": lower case, matched case-insensitively
    /// true: 8-bit values for display (the Display chain, docs/scene-format.md "Output and
    /// display colour"); false: the framebuffer's linear values.
    bool display_encoded = false;
    /// Encodes the image into `sink` in file order; false when options.cancel was set. Null
    /// for a format whose writer must seek in its file (then `write_file` is set).
    bool (*encode)(const Framebuffer&, const Display&, const ByteSink&, const WriteOptions&) = nullptr;
    /// Writes the image into the open file `fd` (named `path` in messages); false when
    /// cancelled. Null when `encode` is set.
    bool (*write_file)(int fd, const std::string& path, const Framebuffer&, const Display&,
                       const WriteOptions&) = nullptr;
    /// Reads a file of this format back (the linear values, or the stored codes / 255 for a
    /// display-encoded format); throws RenderError.
    Framebuffer (*read)(const std::string& path) = nullptr;
    /// Bytes the writer holds besides the framebuffer for a width x height image.
    double (*buffer_bytes)(int width, int height) = nullptr;
};

/// Every registered format, in the order of the list.
std::span<const ImageFormat* const> image_formats();

/// The format named by the path's extension (case-insensitive); nullptr if none is.
const ImageFormat* image_format_for(const std::string& path);

/// The format with this extension (".ppm"); throws std::invalid_argument if none has it.
const ImageFormat& image_format(std::string_view extension);

/// The registered extensions for messages: ".ppm, .png, .pfm, .exr or .hdr".
std::string image_format_extensions();

}  // namespace streamrt
