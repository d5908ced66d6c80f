#include "image/image_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include <unistd.h>

#include "core/error.h"

// The only translation unit that includes stb.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb_image.h>

namespace streamrt {

namespace fs = std::filesystem;

std::optional<ImageFormat> image_format_for(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".ppm") return ImageFormat::Ppm;
    if (ext == ".png") return ImageFormat::Png;
    if (ext == ".pfm") return ImageFormat::Pfm;
    return std::nullopt;
}

Framebuffer calibrate(const Framebuffer& fb, Calibration how) {
    Framebuffer out = fb;
    float scale = 1.f;
    if (how == Calibration::Normalize) {
        float peak = 0.f;
        for (float v : fb.rgb)
            if (std::isfinite(v)) peak = std::max(peak, v);
        if (peak > 0.f) scale = 1.f / peak;
    }
    for (float& v : out.rgb) v = std::isfinite(v) ? std::clamp(v * scale, 0.f, 1.f) : 0.f;
    return out;
}

namespace {

std::vector<unsigned char> to_bytes(const Framebuffer& fb) {
    std::vector<unsigned char> bytes(fb.rgb.size());
    for (std::size_t i = 0; i < fb.rgb.size(); ++i)
        bytes[i] = static_cast<unsigned char>(std::lround(fb.rgb[i] * 255.f));
    return bytes;
}

void stb_write_callback(void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
}

std::string encode(const Framebuffer& fb, ImageFormat format) {
    std::string out;
    if (format == ImageFormat::Ppm) {
        out = "P6\n" + std::to_string(fb.width) + " " + std::to_string(fb.height) + "\n255\n";
        const auto bytes = to_bytes(fb);
        out.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    } else if (format == ImageFormat::Png) {
        const auto bytes = to_bytes(fb);
        if (!stbi_write_png_to_func(stb_write_callback, &out, fb.width, fb.height, 3, bytes.data(),
                                    fb.width * 3))
            throw RenderError("PNG encoding failed");
    } else {
        // PFM: rows bottom to top, little-endian floats (negative scale says so).
        out = "PF\n" + std::to_string(fb.width) + " " + std::to_string(fb.height) + "\n-1.0\n";
        for (int y = fb.height - 1; y >= 0; --y)
            out.append(reinterpret_cast<const char*>(fb.pixel(0, y)), std::size_t(fb.width) * 3 * sizeof(float));
    }
    return out;
}

}  // namespace

void write_image(const std::string& path, const Framebuffer& fb, Calibration how) {
    const auto format = image_format_for(path);
    if (!format) throw RenderError(path + ": unknown image format (expected .ppm, .png or .pfm)");
    // PFM keeps the linear values for error measurement; the 8-bit formats are calibrated.
    const std::string data = encode(*format == ImageFormat::Pfm ? fb : calibrate(fb, how), *format);
    // Temporary name in the same folder, so the rename is atomic.
    const fs::path target(path);
    const fs::path tmp = target.parent_path() /
                         ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
    {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f) throw RenderError(path + ": cannot write: " + std::strerror(errno));
        const bool ok = std::fwrite(data.data(), 1, data.size(), f) == data.size();
        const bool closed = std::fclose(f) == 0;
        if (!ok || !closed) {
            const int err = errno;
            std::remove(tmp.c_str());
            throw RenderError(path + ": write failed: " + std::strerror(err));
        }
    }
    if (std::rename(tmp.c_str(), target.c_str()) != 0) {
        const int err = errno;
        std::remove(tmp.c_str());
        throw RenderError(path + ": cannot rename into place: " + std::strerror(err));
    }
}

namespace {

std::string read_all(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw RenderError(path + ": cannot open");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Reads "P6"/"PF" header fields: whitespace-separated tokens, '#' comments.
struct HeaderReader {
    const std::string& data;
    std::size_t pos = 0;
    std::string token() {
        while (pos < data.size()) {
            if (data[pos] == '#') {
                while (pos < data.size() && data[pos] != '\n') ++pos;
            } else if (std::isspace(static_cast<unsigned char>(data[pos]))) {
                ++pos;
            } else {
                break;
            }
        }
        const std::size_t start = pos;
        while (pos < data.size() && !std::isspace(static_cast<unsigned char>(data[pos]))) ++pos;
        return data.substr(start, pos - start);
    }
};

}  // namespace

Framebuffer read_image(const std::string& path) {
    const auto format = image_format_for(path);
    if (!format) throw RenderError(path + ": unknown image format");
    if (*format == ImageFormat::Png) {
        int w = 0, h = 0, n = 0;
        unsigned char* px = stbi_load(path.c_str(), &w, &h, &n, 3);
        if (!px) throw RenderError(path + ": cannot decode PNG");
        Framebuffer fb(w, h);
        for (std::size_t i = 0; i < fb.rgb.size(); ++i) fb.rgb[i] = px[i] / 255.f;
        stbi_image_free(px);
        return fb;
    }
    const std::string data = read_all(path);
    HeaderReader r{data};
    const std::string magic = r.token();
    const int w = std::atoi(r.token().c_str()), h = std::atoi(r.token().c_str());
    const std::string third = r.token();
    ++r.pos;  // the single whitespace byte before the raster
    if (w <= 0 || h <= 0) throw RenderError(path + ": bad header");
    Framebuffer fb(w, h);
    const std::size_t n = fb.rgb.size();
    if (*format == ImageFormat::Ppm) {
        if (magic != "P6" || third != "255" || data.size() < r.pos + n) throw RenderError(path + ": not a P6 PPM");
        for (std::size_t i = 0; i < n; ++i) fb.rgb[i] = static_cast<unsigned char>(data[r.pos + i]) / 255.f;
    } else {
        if (magic != "PF" || data.size() < r.pos + n * sizeof(float)) throw RenderError(path + ": not an RGB PFM");
        for (int y = 0; y < h; ++y)
            std::memcpy(fb.pixel(0, h - 1 - y), data.data() + r.pos + std::size_t(y) * w * 3 * sizeof(float),
                        std::size_t(w) * 3 * sizeof(float));
    }
    return fb;
}

}  // namespace streamrt
