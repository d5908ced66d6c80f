#pragma once
// Stanford PLY meshes (ASCII, binary little and big endian): the `vertex` element's x y z
// (and nx ny nz when all three are present; texture coordinates u v, s t, texture_u
// texture_v or texture_s texture_t when one pair is; red green blue colours when all three
// are, as linear light) and the `face` element's vertex index
// lists, polygons fan-triangulated, with the faces' per-corner `texcoord` lists when present
// (MeshLab's form); every other element and property is skipped by its size.
// Debian ships no maintained PLY library, hence this reader. Every count and size in the
// header is checked against the file's length before anything is allocated.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/memory_budget.h"

namespace streamrt {

struct Mesh;

/// What a PLY file holds for a mesh.
struct PlyData {
    std::vector<float> positions;          ///< 3 per vertex
    std::vector<float> normals;            ///< 3 per vertex, or empty (no nx ny nz)
    std::vector<std::uint32_t> triangles;  ///< 3 vertex numbers per triangle
    std::vector<float> uvs;                ///< keep_uv: 2 per vertex (u, v), or empty
    std::vector<float> corner_uv;          ///< keep_uv: 6 per triangle (its corners' u, v) from face texcoord lists, or empty
    std::vector<float> colors;             ///< keep_colors: 3 per vertex (red green blue as linear light), or empty
};

/// What parse_ply keeps beside positions, normals and triangles (a large scan's colours are
/// not held for a render that does not show them; their values are then not checked either).
struct PlyReadOptions {
    bool keep_uv = false;      ///< PlyData::uvs and corner_uv
    bool keep_colors = false;  ///< PlyData::colors
    /// What the arrays may take (core/memory_budget.h): each element's arrays are counted from
    /// its declared count before they are allocated; nullptr: no budget.
    MemoryBudget* budget = nullptr;
};

/// Parses the bytes of a PLY file named `name` (for messages). Throws std::runtime_error
/// with one line: `name:line:col: message` for the header and an ASCII body,
/// `name: element E K (byte offset B): message` for a binary body (element E's K-th item,
/// counted from 0).
PlyData parse_ply(std::string_view bytes, const std::string& name, const PlyReadOptions& options = {});

/// Reads a PLY file into a mesh (its normals, when present, are the mesh's vertex normals).
/// With `with_uv` (a textured object) the mesh keeps texture coordinates: the faces'
/// texcoord lists when the file has them, else the vertices' u v. Throws std::runtime_error
/// like parse_ply, for a file with no triangle of non-zero area, and with `with_uv` for a
/// file without texture coordinates. With `with_colors` (a vertex_colors=true object) it keeps
/// the vertices' red green blue (MeshView::vertex_colors), and refuses a file without them.
std::shared_ptr<const Mesh> load_ply_mesh(const std::string& path, bool with_uv = false, bool with_colors = false);

/// The mesh of a file by its extension: `.ply` or `.ply.gz` (any case) with load_ply_mesh,
/// anything else as a Wavefront OBJ file (load_obj_mesh; `.gz` files inflated first,
/// mesh/mesh_bytes.h); `with_uv` and `with_colors` as for those.
std::shared_ptr<const Mesh> load_mesh_file(const std::string& path, bool with_uv, bool with_colors = false);

/// True when `path` names a PLY file (extension `.ply`, or `.ply.gz` compressed; any case).
bool is_ply_path(const std::string& path);

}  // namespace streamrt
