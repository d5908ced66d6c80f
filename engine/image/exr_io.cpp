#include "image/exr_io.h"

#include <algorithm>
#include <cstdint>
#include <new>
#include <system_error>

#include "core/error.h"
#include "core/module_loader.h"
#include "image/exr_codec.h"

namespace streamrt {

namespace {

constexpr std::size_t kPixelBytes = 3 * sizeof(float);
constexpr std::size_t kHalfBytes = 2;  // OpenEXR's half (this side does not include its headers)

/// The OpenEXR module's table, loaded on first use (once per process).
const ExrCodec& exr_codec(const std::string& path) {
    static const ModuleTable<ExrCodec> loaded =
        load_module_table<ExrCodec>(kExrModuleFile, kExrCodecSymbol, kExrCodecVersion, false);
    if (!loaded.table) throw RenderError(path + ": EXR: the OpenEXR module is not available (" + loaded.error + ")");
    return *loaded.table;
}

}  // namespace

bool write_exr(int fd, const std::string& path, const Framebuffer& fb, ExrPixels pixels, const WriteOptions& options) {
    const ExrCodec& codec = exr_codec(path);
    std::string message;
    int code = 0;
    switch (codec.write(fd, path.c_str(), fb.width, fb.height, fb.rgb.data(), pixels == ExrPixels::Half,
                        options.cancel, &message, &code)) {
        case ExrStatus::Done: return true;
        case ExrStatus::Cancelled: return false;
        case ExrStatus::SystemError: throw std::system_error(code, std::generic_category());
        case ExrStatus::OutOfMemory: throw std::bad_alloc();
        case ExrStatus::Failed: break;
    }
    throw RenderError(path + ": " + message);
}

Framebuffer read_exr(const std::string& path) {
    const ExrCodec& codec = exr_codec(path);
    Framebuffer fb;
    auto allocate = [](void* context, int w, int h) {
        Framebuffer& f = *static_cast<Framebuffer*>(context);
        f = Framebuffer::uninitialized(w, h);
        return f.rgb.data();
    };
    std::string message;
    switch (codec.read(path.c_str(), allocate, &fb, &message)) {
        case ExrStatus::Done: return fb;
        case ExrStatus::OutOfMemory: throw std::bad_alloc();
        case ExrStatus::Cancelled:
        case ExrStatus::SystemError:
        case ExrStatus::Failed: break;
    }
    throw RenderError(path + ": " + message);
}

double exr_write_buffer_bytes(int width, int height) {
    // A band of half rows; OpenEXR's line buffer of kExrZipLines lines at up to 12 bytes a
    // pixel, about as much again for the compressor's input and output; 8 bytes of offset
    // per block.
    const double band = double(std::min(exr_band_rows(width), height)) * double(width) * 3 * kHalfBytes;
    const double lines = double(kExrZipLines) * double(width) * double(kPixelBytes);
    return band + 3 * lines + 8.0 * (double(height) / kExrZipLines + 1);
}

namespace {
bool write_exr_file(int fd, const std::string& path, const Framebuffer& fb, const Display& display,
                    const WriteOptions& options) {
    return write_exr(fd, path, fb, display.exr, options);
}
}  // namespace

// The writer seeks back for its line offset table: written to the file, not to a byte sink.
extern const ImageFormat kExrFormat{"EXR", ".exr", false, nullptr, &write_exr_file, &read_exr, &exr_write_buffer_bytes};

}  // namespace streamrt
