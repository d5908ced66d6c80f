// libFuzzer target for the PLY reader alone: parse_ply() on arbitrary bytes must either
// return data whose triangles address its vertices or throw std::runtime_error with one
// line; never crash, read out of bounds or allocate beyond the input's size (ASan's
// -rss_limit_mb and -malloc_limit_mb catch that). The same bytes go through the gzip
// inflater of `.ply.gz` files (mesh/mesh_bytes.h), which must end, within its limit, or
// throw one line. Built and run by scripts/fuzz.sh ply.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "mesh/mesh_bytes.h"
#include "mesh/ply_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        const streamrt::PlyData d = streamrt::parse_ply(std::string_view(reinterpret_cast<const char*>(data), size), "f.ply",
                                                        {.keep_uv = true, .keep_colors = true});
        const std::size_t vertices = d.positions.size() / 3;
        if (d.positions.size() % 3 || d.triangles.size() % 3 || (!d.normals.empty() && d.normals.size() != d.positions.size()))
            std::abort();
        for (std::uint32_t v : d.triangles)
            if (v >= vertices) std::abort();
        // Texture coordinates and colours: per vertex or per corner, finite, colours >= 0.
        if ((!d.uvs.empty() && d.uvs.size() != 2 * vertices) || (!d.colors.empty() && d.colors.size() != 3 * vertices) ||
            (!d.corner_uv.empty() && d.corner_uv.size() != 2 * d.triangles.size()))
            std::abort();
        for (float c : d.colors)
            if (!(c >= 0.f) || !std::isfinite(c)) std::abort();
    } catch (const std::runtime_error& e) {
        if (std::string_view(e.what()).find('\n') != std::string_view::npos) std::abort();
    }
    try {
        constexpr std::size_t kLimit = std::size_t(1) << 20;
        if (streamrt::inflate_gzip(std::string_view(reinterpret_cast<const char*>(data), size), kLimit).size() > kLimit)
            std::abort();
    } catch (const std::runtime_error& e) {
        if (std::string_view(e.what()).find('\n') != std::string_view::npos) std::abort();
    }
    return 0;
}
