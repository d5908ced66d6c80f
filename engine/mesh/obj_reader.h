#pragma once
// Wavefront OBJ geometry, streamrt's own reader (tinyobjloader read 20-40 MB/s, one thread).
// The text is cut into chunks at line ends and the chunks are parsed in parallel
// (parallel/parallelism.h) in two passes: the first counts each chunk's v, vt and vn lines, so
// the second knows how many come before it, resolves every face index (relative ones too)
// exactly as a sequential reader would, checks it and writes the positions in place. Numbers
// are read with std::from_chars (correctly rounded to float). Faces are triangulated as
// tinyobjloader did, so meshes are the triangles they always were: a quad along its shorter
// diagonal, a larger polygon by its ear clipping. The result does not depend on the thread
// count. Every error is one line, `file:line:col: message` (docs/scene-format.md, "mesh").
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/memory_budget.h"

namespace streamrt {

/// What an OBJ file holds for meshes. `vn` lines are counted (faces may refer to them) but
/// their values are not read: the renderer computes its normals (Mesh::build).
struct ObjData {
    static constexpr std::uint32_t kNoUv = 0xffffffffu;
    std::vector<float> positions;          ///< 3 per `v` (a w or a colour after x y z is not kept here)
    /// ObjReadOptions::keep_colors only: 3 per `v`, the r g b of a `v x y z r g b [a]` line as
    /// written (0 where a line has none; colorless_offset names the first such line).
    std::vector<float> colors;
    std::size_t colorless_offset = std::size_t(-1);  ///< keep_colors: the first `v` without a colour, or -1
    std::vector<float> texcoords;          ///< 2 per `vt` (a missing second value is 0)
    std::size_t normal_count = 0;          ///< `vn` lines
    std::vector<std::uint32_t> triangles;  ///< 3 vertex numbers (from 0) per triangle, file order
    /// ObjReadOptions::keep_uv only: 3 `vt` numbers per triangle, kNoUv for a corner without.
    std::vector<std::uint32_t> triangle_uv;
    /// A `usemtl` line: the triangles from first_triangle on (up to the next) use `name`.
    struct MaterialUse {
        std::size_t first_triangle = 0;
        std::string name;
        bool before_library = false;  ///< before the first `mtllib` line (names no material there)
    };
    std::vector<MaterialUse> material_uses;
    /// keep_uv only: the first face with a corner without `vt` (its first triangle and the
    /// corner's byte offset, for obj_fail_at) of each run of faces from the file's start or a
    /// `usemtl` line to the next.
    struct UvGap {
        std::size_t triangle = 0;
        std::size_t offset = 0;
    };
    std::vector<UvGap> uv_gaps;
    std::string mtllib;  ///< the file named by the first `mtllib` line that names one; empty: none
};

struct ObjReadOptions {
    bool keep_uv = false;              ///< fill triangle_uv and uv_gaps
    bool keep_colors = false;          ///< fill colors and colorless_offset
    std::size_t chunk_bytes = 1 << 20;  ///< a chunk's size, extended to the next line end (tests: tiny)
    std::size_t max_vertices = 0xffffffffu;  ///< more are refused (vertex numbers are 32-bit)
    /// What the arrays may take (core/memory_budget.h): counted before they are allocated
    /// (vertices once counted, faces chunk by chunk as they are read); nullptr: no budget.
    MemoryBudget* budget = nullptr;
};

/// Parses the bytes of an OBJ file named `name` (for messages). Throws std::runtime_error with
/// one line, `name:line:col: message`, at the first error in the file: a malformed number or
/// index, a coordinate that is not finite or beyond the float range, an index of 0 or out of
/// range, a face of fewer than 3 corners, more than options.max_vertices vertices.
ObjData parse_obj(std::string_view bytes, const std::string& name, const ObjReadOptions& options = {});

/// Throws std::runtime_error(`name:line:col: message`) for byte `offset` of `bytes`.
[[noreturn]] void obj_fail_at(std::string_view bytes, const std::string& name, std::size_t offset,
                              const std::string& message);

}  // namespace streamrt
