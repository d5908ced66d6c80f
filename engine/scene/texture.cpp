#include "scene/texture.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>

// stb_image's decoder, private to this file (image/image_io.cpp has its own PNG-only copy).
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_image.h>
#pragma GCC diagnostic pop

#include "core/srgb.h"

namespace streamrt {

std::size_t Texture::memory_bytes() const {
    std::size_t b = 0;
    for (const auto& d : data) b += d.size() * sizeof(float);
    return b;
}

std::shared_ptr<const Texture> Texture::build(std::string name, int width, int height, std::vector<float> rgb) {
    auto t = std::make_shared<Texture>();
    t->name = std::move(name);
    t->data.push_back(std::move(rgb));
    std::vector<std::pair<int, int>> sizes{{width, height}};
    while (sizes.back().first > 1 || sizes.back().second > 1) {
        const auto [w, h] = sizes.back();
        const int nw = std::max(1, w / 2), nh = std::max(1, h / 2);
        const std::vector<float>& src = t->data.back();
        std::vector<float> dst(std::size_t(nw) * std::size_t(nh) * 3);
        for (int y = 0; y < nh; ++y) {
            // Source rows 2y, 2y + 1 (and 2y + 2 for the last row of an odd height).
            const int y0 = std::min(2 * y, h - 1), y1 = (y == nh - 1) ? h - 1 : std::min(2 * y + 1, h - 1);
            for (int x = 0; x < nw; ++x) {
                const int x0 = std::min(2 * x, w - 1), x1 = (x == nw - 1) ? w - 1 : std::min(2 * x + 1, w - 1);
                double sum[3] = {0, 0, 0};
                for (int sy = y0; sy <= y1; ++sy)
                    for (int sx = x0; sx <= x1; ++sx)
                        for (int c = 0; c < 3; ++c)
                            sum[c] += src[(std::size_t(sy) * std::size_t(w) + std::size_t(sx)) * 3 + std::size_t(c)];
                const double n = double((y1 - y0 + 1) * (x1 - x0 + 1));
                for (int c = 0; c < 3; ++c)
                    dst[(std::size_t(y) * std::size_t(nw) + std::size_t(x)) * 3 + std::size_t(c)] = float(sum[c] / n);
            }
        }
        t->data.push_back(std::move(dst));
        sizes.emplace_back(nw, nh);
    }
    for (std::size_t i = 0; i < sizes.size(); ++i)
        t->levels.push_back({t->data[i].data(), sizes[i].first, sizes[i].second});
    return t;
}

namespace {
/// Refuses (closing f) an image larger than kMaxTextureSide / kMaxTextureTexels.
void check_size(std::FILE* f, std::uint32_t w, std::uint32_t h) {
    if (w <= std::uint32_t(kMaxTextureSide) && h <= std::uint32_t(kMaxTextureSide) &&
        std::size_t(w) * std::size_t(h) <= kMaxTextureTexels)
        return;
    std::fclose(f);
    throw std::runtime_error("image of " + std::to_string(w) + " x " + std::to_string(h) +
                             " texels is too large for a texture (at most " + std::to_string(kMaxTextureSide) +
                             " per side and " + std::to_string(kMaxTextureTexels) + " texels in all)");
}
}  // namespace

std::shared_ptr<const Texture> load_texture(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw std::runtime_error("cannot open texture file");
    int w = 0, h = 0, n = 0;
    // A PNG's size is read from its IHDR here: stb_image refuses huge PNGs in its header
    // scan but then reports the last format it tried ("unknown image type").
    unsigned char head[24];
    const bool png = std::fread(head, 1, 24, f) == 24 && std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) == 0 &&
                     std::memcmp(head + 12, "IHDR", 4) == 0;
    std::rewind(f);
    const auto be32 = [&](int at) {
        return (std::uint32_t(head[at]) << 24) | (std::uint32_t(head[at + 1]) << 16) |
               (std::uint32_t(head[at + 2]) << 8) | std::uint32_t(head[at + 3]);
    };
    if (png) check_size(f, be32(16), be32(20));
    if (!stbi_info_from_file(f, &w, &h, &n)) {
        std::fclose(f);
        throw std::runtime_error(std::string("not a readable PNG or JPEG image (") + stbi_failure_reason() + ")");
    }
    check_size(f, std::uint32_t(w), std::uint32_t(h));
    unsigned char* px = stbi_load_from_file(f, &w, &h, &n, 3);
    std::fclose(f);
    if (!px) throw std::runtime_error(std::string("cannot decode image (") + stbi_failure_reason() + ")");
    std::vector<float> rgb(std::size_t(w) * std::size_t(h) * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = srgb_to_linear(px[i]);
    stbi_image_free(px);
    return Texture::build(path, w, h, std::move(rgb));
}

}  // namespace streamrt
