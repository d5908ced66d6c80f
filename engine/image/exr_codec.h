#pragma once
// The OpenEXR module's table (engine/modules/exr_codec.cpp, built as libstreamrt_exr.so and
// loaded on the first .exr read or write by image/exr_io.cpp): plain types across the
// boundary, errors as status codes, so the module can be loaded with its own symbols kept
// to itself.
#include <algorithm>
#include <atomic>
#include <string>

namespace streamrt {

/// Rows per band of half pixels written at a time (~256 KiB of halves).
inline int exr_band_rows(int width) { return std::max(1, (256 << 10) / (std::max(width, 1) * 6)); }
/// Lines per ZIP block: ZIPS_COMPRESSION, one scanline per block.
inline constexpr int kExrZipLines = 1;

enum class ExrStatus : int { Done = 0, Cancelled = 1, Failed = 2, SystemError = 3, OutOfMemory = 4 };

struct ExrCodec {
    int version;
    /// Writes width x height RGB floats (row-major from the top-left) to `fd` as scanline
    /// ZIPS, half or float channels. Failed: `message` says why; SystemError: `code` is errno.
    ExrStatus (*write)(int fd, const char* path, int width, int height, const float* rgb, bool half,
                       const std::atomic<bool>* cancel, std::string* message, int* code);
    /// Reads the R, G, B channels into the room `allocate(context, width, height)` returns
    /// (width x height x 3 floats).
    ExrStatus (*read)(const char* path, float* (*allocate)(void* context, int width, int height), void* context,
                      std::string* message);
};

inline constexpr int kExrCodecVersion = 1;
inline constexpr const char* kExrModuleFile = "libstreamrt_exr.so";
inline constexpr const char* kExrCodecSymbol = "streamrt_exr_codec";

}  // namespace streamrt
