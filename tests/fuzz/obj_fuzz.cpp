// libFuzzer target for the OBJ reader alone: parse_obj() on arbitrary bytes must either return
// data whose triangles address its vertices and texture coordinates, with finite positions, or
// throw std::runtime_error with one printable line `f.obj:LINE:COL: message`; and read in
// 7-byte chunks (every chunk seam crossed) exactly as in one, vertex colours included. Built and run by
// scripts/fuzz.sh obj.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "mesh/obj_reader.h"

namespace {

using streamrt::ObjData;

/// The data, or the error's text.
std::string read(std::string_view text, std::size_t chunk, ObjData& out) {
    try {
        out = streamrt::parse_obj(text, "f.obj", {.keep_uv = true, .keep_colors = true, .chunk_bytes = chunk});
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        for (unsigned char c : what)
            if (c < 0x20 || c == 0x7f) std::abort();
        if (what.rfind("f.obj:", 0) != 0 || what.find(": ", 6) == std::string::npos) std::abort();
        return what;
    }
    return "";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    ObjData a, b;
    const std::string ea = read(text, 7, a), eb = read(text, std::size_t(1) << 20, b);
    if (ea != eb) std::abort();
    if (!ea.empty()) return 0;
    const std::size_t vertices = a.positions.size() / 3, texcoords = a.texcoords.size() / 2;
    if (a.positions.size() % 3 || a.texcoords.size() % 2 || a.triangles.size() % 3 ||
        a.triangle_uv.size() != a.triangles.size())
        std::abort();
    for (float p : a.positions)
        if (!std::isfinite(p)) std::abort();
    for (std::uint32_t v : a.triangles)
        if (v >= vertices) std::abort();
    for (std::uint32_t t : a.triangle_uv)
        if (t != ObjData::kNoUv && t >= texcoords) std::abort();
    // Colours: one per vertex, the first vertex without one the same at every chunk size.
    if (a.colors.size() != a.positions.size() || a.colors != b.colors || a.colorless_offset != b.colorless_offset ||
        (a.colorless_offset != std::size_t(-1) && a.colorless_offset >= text.size()))
        std::abort();
    if (a.positions != b.positions || a.texcoords != b.texcoords || a.triangles != b.triangles ||
        a.triangle_uv != b.triangle_uv || a.mtllib != b.mtllib || a.material_uses.size() != b.material_uses.size() ||
        a.uv_gaps.size() != b.uv_gaps.size())
        std::abort();
    for (std::size_t k = 0; k < a.material_uses.size(); ++k)
        if (a.material_uses[k].first_triangle != b.material_uses[k].first_triangle ||
            a.material_uses[k].name != b.material_uses[k].name ||
            a.material_uses[k].before_library != b.material_uses[k].before_library)
            std::abort();
    for (std::size_t k = 0; k < a.uv_gaps.size(); ++k)
        if (a.uv_gaps[k].triangle != b.uv_gaps[k].triangle || a.uv_gaps[k].offset != b.uv_gaps[k].offset) std::abort();
    return 0;
}
