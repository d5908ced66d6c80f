#include "image/exr_io.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <exception>
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

#include "core/error.h"

namespace streamrt {

namespace {

// Rows handed to OpenEXR between two looks at the cancel flag: about 256 KiB of half pixels.
int exr_band_rows(int width) { return std::max(1, (256 << 10) / (std::max(width, 1) * 6)); }
constexpr int kZipLines = 1;  // lines per ZIP block: ZIPS_COMPRESSION, one scanline per block
constexpr std::size_t kPixelBytes = 3 * sizeof(float);

// OpenEXR's output stream on our temporary file: positioned writes, since the writer goes
// back to fill in the line offset table at the end.
class FdStream final : public Imf::OStream {
  public:
    FdStream(int fd, const std::string& name) : Imf::OStream(name.c_str()), fd_(fd) {}
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

// A slice over channel c (0 R, 1 G, 2 B) of interleaved RGB rows of `width` pixels of type
// T at `data`, holding pixel (x0, y0) first: OpenEXR addresses pixel (x, y) at
// base + x * xStride + y * yStride, so the base is moved back by (x0, y0).
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

}  // namespace

bool write_exr(int fd, const std::string& path, const Framebuffer& fb, ExrPixels pixels, const WriteOptions& options) {
    try {
        Imf::Header header(fb.width, fb.height);
        // ZIPS: deflate per scanline. ZIP's 16-line blocks compress a little better but make
        // OpenEXR hold 16 lines three times over (19 MB at width 32768, more than the PNG
        // writer's bands); with one line the writer stays within a few hundred KiB.
        header.compression() = Imf::ZIPS_COMPRESSION;
        const Imf::PixelType type = pixels == ExrPixels::Half ? Imf::HALF : Imf::FLOAT;
        for (const char* name : kChannels) header.channels().insert(name, Imf::Channel(type));
        FdStream stream(fd, path);
        Imf::OutputFile file(stream, header, 0);  // 0: compress on this thread
        // Float files take the framebuffer as it is; half files a band at a time, rounded to
        // the nearest half (Imath's conversion; OpenEXR's writer does not convert).
        std::vector<half> band;
        if (type == Imf::FLOAT) file.setFrameBuffer(rgb_slices(Imf::FLOAT, fb.rgb.data(), fb.width, 0, 0));
        const int band_rows = exr_band_rows(fb.width);
        if (type == Imf::HALF) band.resize(std::size_t(std::min(band_rows, fb.height)) * std::size_t(fb.width) * 3);
        for (int y = 0; y < fb.height; y += band_rows) {
            if (options.cancel && options.cancel->load()) return false;
            const int rows = std::min(band_rows, fb.height - y);
            if (type == Imf::HALF) {
                const float* from = fb.pixel(0, y);
                for (std::size_t i = 0; i < std::size_t(rows) * std::size_t(fb.width) * 3; ++i) band[i] = half(from[i]);
                file.setFrameBuffer(rgb_slices(Imf::HALF, band.data(), fb.width, 0, y));
            }
            file.writePixels(rows);
        }
        return true;
    } catch (const std::system_error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        throw RenderError(path + ": EXR: " + e.what());
    }
}

Framebuffer read_exr(const std::string& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        const std::int64_t w = std::int64_t(window.max.x) - window.min.x + 1,
                           h = std::int64_t(window.max.y) - window.min.y + 1;
        if (w <= 0 || h <= 0 || w > 65536 || h > 65536) throw RenderError(path + ": EXR: unsupported data window");
        Framebuffer fb = Framebuffer::uninitialized(int(w), int(h));
        file.setFrameBuffer(rgb_slices(Imf::FLOAT, fb.rgb.data(), fb.width, window.min.x, window.min.y));
        file.readPixels(window.min.y, window.max.y);
        return fb;
    } catch (const RenderError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        throw RenderError(path + ": cannot read EXR: " + e.what());
    }
}

double exr_write_buffer_bytes(int width, int height) {
    // A band of half rows; OpenEXR's line buffer of kZipLines lines at up to 12 bytes a
    // pixel, about as much again for the compressor's input and output; 8 bytes of offset
    // per block.
    const double band = double(std::min(exr_band_rows(width), height)) * double(width) * 3 * sizeof(half);
    const double lines = double(kZipLines) * double(width) * double(kPixelBytes);
    return band + 3 * lines + 8.0 * (double(height) / kZipLines + 1);
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
