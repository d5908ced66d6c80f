// libstreamrt_exr.so: OpenEXR behind the plain table of image/exr_codec.h. Loaded by
// image/exr_io.cpp on the first .exr read or write, so runs that never touch an .exr file do
// not load OpenEXR at start-up.
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <exception>
#include <new>
#include <system_error>
#include <vector>

#include <unistd.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <Imath/half.h>

#include "image/exr_codec.h"

namespace {

using streamrt::ExrStatus;

/// OpenEXR's output stream on the caller's temporary file: positioned writes, since the
/// writer goes back to fill in the line offset table at the end.
class FdStream final : public Imf::OStream {
  public:
    FdStream(int fd, const char* name) : Imf::OStream(name), fd_(fd) {}
    void write(const char c[], int n) override {
        for (std::size_t done = 0; done < std::size_t(n);) {
            const ssize_t k = ::pwrite(fd_, c + done, std::size_t(n) - done, off_t(pos_ + done));
            if (k < 0) {
                if (errno == EINTR) continue;
                throw std::system_error(errno, std::generic_category());
            }
            done += std::size_t(k);
        }
        pos_ += std::uint64_t(n);
    }
    std::uint64_t tellp() override { return pos_; }
    void seekp(std::uint64_t pos) override { pos_ = pos; }

  private:
    int fd_;
    std::uint64_t pos_ = 0;
};

/// A slice over channel c (0 R, 1 G, 2 B) of interleaved RGB rows of `width` pixels of type
/// T at `data`, holding pixel (x0, y0) first: OpenEXR addresses pixel (x, y) at
/// base + x * xStride + y * yStride, so the base is moved back by (x0, y0).
template <class T>
Imf::Slice channel_slice(Imf::PixelType type, T* data, int width, int c, int x0, int y0) {
    const std::size_t pixel = 3 * sizeof(T), row = std::size_t(width) * pixel;
    const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(data + c);
    const std::uintptr_t origin = std::uintptr_t(std::intptr_t(x0) * std::intptr_t(pixel) +
                                                 std::intptr_t(y0) * std::intptr_t(row));
    return Imf::Slice(type, reinterpret_cast<char*>(start - origin), pixel, row, 1, 1, 0.0);
}

const char* const kChannels[3] = {"R", "G", "B"};

template <class T>
Imf::FrameBuffer rgb_slices(Imf::PixelType type, T* data, int width, int x0, int y0) {
    Imf::FrameBuffer slices;
    for (int c = 0; c < 3; ++c) slices.insert(kChannels[c], channel_slice(type, data, width, c, x0, y0));
    return slices;
}

ExrStatus write_exr(int fd, const char* path, int width, int height, const float* rgb, bool half_pixels,
                    const std::atomic<bool>* cancel, std::string* message, int* code) {
    try {
        Imf::Header header(width, height);
        header.compression() = Imf::ZIPS_COMPRESSION;
        const Imf::PixelType type = half_pixels ? Imf::HALF : Imf::FLOAT;
        for (const char* name : kChannels) header.channels().insert(name, Imf::Channel(type));
        FdStream stream(fd, path);
        Imf::OutputFile file(stream, header, 0);  // 0: compress on this thread
        std::vector<half> band;
        // OpenEXR's slices take a non-const pointer; the writer only reads through it.
        float* pixels = const_cast<float*>(rgb);
        if (type == Imf::FLOAT) file.setFrameBuffer(rgb_slices(Imf::FLOAT, pixels, width, 0, 0));
        const int band_rows = streamrt::exr_band_rows(width);
        if (type == Imf::HALF) band.resize(std::size_t(std::min(band_rows, height)) * std::size_t(width) * 3);
        for (int y = 0; y < height; y += band_rows) {
            if (cancel && cancel->load()) return ExrStatus::Cancelled;
            const int rows = std::min(band_rows, height - y);
            if (type == Imf::HALF) {
                const float* from = rgb + std::size_t(y) * std::size_t(width) * 3;
                for (std::size_t i = 0; i < std::size_t(rows) * std::size_t(width) * 3; ++i) band[i] = half(from[i]);
                file.setFrameBuffer(rgb_slices(Imf::HALF, band.data(), width, 0, y));
            }
            file.writePixels(rows);
        }
        return ExrStatus::Done;
    } catch (const std::system_error& e) {
        *code = e.code().value();
        return ExrStatus::SystemError;
    } catch (const std::bad_alloc&) {
        return ExrStatus::OutOfMemory;
    } catch (const std::exception& e) {
        *message = std::string("EXR: ") + e.what();
        return ExrStatus::Failed;
    }
}

ExrStatus read_exr(const char* path, float* (*allocate)(void*, int, int), void* context, std::string* message) {
    try {
        Imf::InputFile file(path);
        const Imath::Box2i window = file.header().dataWindow();
        const std::int64_t w = std::int64_t(window.max.x) - window.min.x + 1,
                           h = std::int64_t(window.max.y) - window.min.y + 1;
        if (w <= 0 || h <= 0 || w > 65536 || h > 65536) {
            *message = "EXR: unsupported data window";
            return ExrStatus::Failed;
        }
        float* rgb = allocate(context, int(w), int(h));
        file.setFrameBuffer(rgb_slices(Imf::FLOAT, rgb, int(w), window.min.x, window.min.y));
        file.readPixels(window.min.y, window.max.y);
        return ExrStatus::Done;
    } catch (const std::bad_alloc&) {
        return ExrStatus::OutOfMemory;
    } catch (const std::exception& e) {
        *message = std::string("cannot read EXR: ") + e.what();
        return ExrStatus::Failed;
    }
}

constexpr streamrt::ExrCodec kCodec{streamrt::kExrCodecVersion, &write_exr, &read_exr};

}  // namespace

extern "C" __attribute__((visibility("default"))) const streamrt::ExrCodec* streamrt_exr_codec() { return &kCodec; }
