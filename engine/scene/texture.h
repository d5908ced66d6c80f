#pragma once
// Image textures (material key texture=FILE): the texels of one PNG or JPEG file as linear
// float RGB with their mip chain, read once per file and shared by every material naming it
// (Scene::textures). The lookup that filters them is render/texture.h.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace streamrt {

/// One level of a mip chain as the engines read it: raw pointers only (the per-ISA kernel
/// files touch no container code). Rows top to bottom, 3 floats (linear RGB) per texel.
struct TextureLevelView {
    const float* rgb;
    std::int32_t width, height;
};

/// What a material holds of its texture: the levels, finest first (none: no texture).
struct TextureView {
    const TextureLevelView* levels = nullptr;
    std::int32_t count = 0;
    explicit operator bool() const { return count > 0; }
};

/// The largest image a texture may be: both sides at most kMaxTextureSide and at most
/// kMaxTextureTexels texels (4096 x 4096), i.e. 256 MiB of float texels with the mip chain
/// (12 bytes a texel, times 4/3). The size is read from the file's header before any
/// decoding, so a larger image (an 80000 x 80000 PNG) is refused without allocating it.
inline constexpr int kMaxTextureSide = 16384;
inline constexpr std::size_t kMaxTextureTexels = std::size_t(1) << 24;

struct Texture {
    std::string name;  ///< the file it came from, for messages
    std::vector<std::vector<float>> data;  ///< per level, linear RGB
    std::vector<TextureLevelView> levels;  ///< per level, pointing into data

    TextureView view() const { return {levels.data(), std::int32_t(levels.size())}; }
    std::size_t memory_bytes() const;

    /// A texture from linear RGB texels (width * height * 3, rows top to bottom); builds the
    /// mip chain: each level halves both sides (rounding down, at least 1) and each texel is
    /// the mean of the 2 x 2 texels above it (a box filter in linear light; an odd last row
    /// or column is folded into the texel before it, 2 x 3 or 3 x 3).
    static std::shared_ptr<const Texture> build(std::string name, int width, int height, std::vector<float> rgb);
};

/// Reads a PNG or JPEG file (stb_image) into a texture, its texels converted from 8-bit sRGB
/// to linear float (alpha ignored, grey expanded to RGB). Throws std::runtime_error with a
/// message (no location) for a missing, unreadable or undecodable file, or one larger than
/// the limits above.
std::shared_ptr<const Texture> load_texture(const std::string& path);

}  // namespace streamrt
