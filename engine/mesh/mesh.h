#pragma once
// Triangle meshes: the triangles of one OBJ file (or a generated surface) in the mesh's own
// coordinates, which are the canonical space of every object that uses it (placed by Md like
// the canonical shapes). Each mesh has its own BVH (accel::Bvh over the triangle boxes) and
// is stored once however many objects use it: the scene hierarchy holds instances.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "core/default_init.h"
#include "mesh/mesh_view.h"
#include "simd/lanes.h"

namespace streamrt {

/// MeshView::single_ray_lanes of every built mesh: a threshold for every packet, whatever its
/// rays (for measurements and tests). Measured (docs/performance.md "### Meshes",
/// perf/mesh_walk_bench): the packet walk alone is fastest for primary, shadow, mirror and
/// glass rays in the engine's tile order. The stream engine hands only packets that have
/// scattered to the single-ray walk (AccelConfig::mesh_hybrid_lanes, --mesh-hybrid).
inline constexpr std::uint32_t kDefaultSingleRayLanes = 0;

struct Mesh {
    std::string name;                   ///< the file it came from, for messages
    std::vector<float> positions;       ///< 3 per vertex the triangles use (MeshView::positions)
    FillLaterVec<std::uint32_t> index;  ///< 3 vertex numbers per triangle, leaf order (written once, in parallel)
    std::vector<float> vertex_normals;  ///< 3 per vertex
    std::vector<float> corner_uv;       ///< 6 per triangle (MeshView::uv), leaf order; empty: none
    std::vector<float> vertex_colors;   ///< 3 per vertex (MeshView::vertex_colors); empty: none
    accel::Bvh bvh;                     ///< prim_index is dropped: triangles are stored in leaf order
    AlignedFillLaterVec<TriangleBlock> blocks;  ///< MeshView::blocks: the leaves' triangles, 4 to a block
    std::vector<std::uint32_t> block_of;     ///< MeshView::block_of, one per triangle
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  ///< bounds of the vertices
    std::size_t dropped = 0;            ///< degenerate triangles left out
    float uv_density = 1.f;            ///< MeshView::uv_density
    MeshView kernel_view{};             ///< pointers into the above, set once built (stable: the mesh is immutable)

    std::size_t triangle_count() const { return index.size() / 3; }
    /// Corner j (0 - 2) of triangle k (leaf order): 3 floats.
    const float* corner(std::size_t k, int j) const { return &positions[3 * std::size_t(index[3 * k + std::size_t(j)])]; }
    /// Triangle k's corners p0, p1, p2 as 9 floats (tests and benchmarks).
    std::array<float, 9> triangle(std::size_t k) const {
        std::array<float, 9> t;
        for (int j = 0; j < 3; ++j)
            for (int a = 0; a < 3; ++a) t[std::size_t(3 * j + a)] = corner(k, j)[a];
        return t;
    }
    const MeshView& view() const { return kernel_view; }
    /// Bytes held by the mesh (positions, vertex numbers, triangle blocks, normals, BVH nodes).
    std::size_t memory_bytes() const;
    /// A copy whose kernels switch a packet to single rays at `lanes` active lanes or fewer
    /// (MeshView::single_ray_lanes), for measuring the switch point (perf/mesh_bench.cpp).
    std::shared_ptr<const Mesh> with_single_ray_lanes(std::uint32_t lanes) const;
    /// About the most build() holds at once beyond its inputs, for a mesh of `vertices` and
    /// `triangles` (with texture coordinates, with colours): what a reader counts against its
    /// memory budget before it builds (core/memory_budget.h).
    static double build_bytes(std::size_t vertices, std::size_t triangles, bool uv, bool colors);
    /// Fills blocks and block_of from the triangles and the BVH's leaves (mesh_blocks.cpp).
    void build_triangle_blocks();
    /// Points kernel_view at this mesh's arrays.
    void set_view(std::uint32_t single_ray_lanes);

    /// Builds a mesh from vertex positions (3 floats each) and triangles (3 vertex numbers
    /// each, counter-clockwise seen from outside). Triangles with a repeated vertex, an
    /// out-of-range vertex or zero area are dropped. May return a mesh with no triangles.
    /// `corner_uv`, when not empty, holds 6 floats per triangle of `triangles` (its corners'
    /// texture coordinates), kept with the triangles. `normals`, when it holds 3 floats per
    /// vertex (a PLY file's nx ny nz), gives the vertex normals (normalised; a zero or
    /// non-finite one is replaced by the computed one); otherwise they are area-weighted.
    /// `colors`, when it holds 3 floats per vertex, gives the vertex colours (linear RGB).
    /// The mesh keeps only the vertices its triangles use, renumbered in their order. Given its
    /// arrays by rvalue, it takes the positions over when it uses every vertex (no copy) and
    /// sorts out the triangles in their own array (a build needs 12 bytes a triangle less).
    static std::shared_ptr<const Mesh> build(std::string name, const std::vector<float>& positions,
                                             const std::vector<std::uint32_t>& triangles,
                                             const accel::BuildOptions& options = {},
                                             const std::vector<float>& corner_uv = {},
                                             const std::vector<float>& normals = {},
                                             const std::vector<float>& colors = {}) {
        return build_from(std::move(name), positions, nullptr, triangles, nullptr, options, corner_uv, normals, colors);
    }
    static std::shared_ptr<const Mesh> build(std::string name, std::vector<float>&& positions,
                                             std::vector<std::uint32_t>&& triangles,
                                             const accel::BuildOptions& options = {},
                                             const std::vector<float>& corner_uv = {},
                                             const std::vector<float>& normals = {},
                                             const std::vector<float>& colors = {}) {
        return build_from(std::move(name), positions, &positions, triangles, &triangles, options, corner_uv, normals,
                          colors);
    }

private:
    /// build's body; `own_positions` and `own_triangles`, when not null, are `positions` and
    /// `triangles`, which it may then move from.
    static std::shared_ptr<const Mesh> build_from(std::string name, const std::vector<float>& positions,
                                                  std::vector<float>* own_positions,
                                                  const std::vector<std::uint32_t>& triangles,
                                                  std::vector<std::uint32_t>* own_triangles,
                                                  const accel::BuildOptions& options,
                                                  const std::vector<float>& corner_uv,
                                                  const std::vector<float>& normals,
                                                  const std::vector<float>& colors);
};

/// Reads a Wavefront OBJ file (mesh/obj_reader.h; polygons are triangulated, materials and
/// normals in the file are ignored). Texture coordinates (vt) are kept only when `with_uv`
/// (a textured object uses the mesh); then every face must have them. Vertex colours (`v x y
/// z r g b`, display values in [0, 1], decoded from sRGB) only when `with_colors` (a
/// vertex_colors=true object); then every vertex must have one. Throws
/// std::runtime_error for a missing or unreadable file (no location), a malformed one or
/// (with_uv) a face without texture coordinates (`file:line:col: message`), or one with no
/// triangles of non-zero area.
std::shared_ptr<const Mesh> load_obj_mesh(const std::string& path, bool with_uv = false, bool with_colors = false);

/// One material of an OBJ file's material library (MTL), as read (docs/scene-format.md,
/// "OBJ materials" maps it onto the material keys).
struct ObjMaterial {
    std::string name;
    double kd[3] = {0, 0, 0};  ///< Kd
    double ks[3] = {0, 0, 0};  ///< Ks
    double ns = 0;             ///< Ns
    double ni = 1;             ///< Ni
    double d = 1;              ///< d (1: opaque)
    std::string map_kd;        ///< map_Kd, relative to the MTL file's folder; empty: none
};

/// An OBJ file read with its materials (mesh materials=obj): one mesh per material used by
/// its faces (usemtl groups; faces before any usemtl form the part of material -1), all cut
/// from the file's one vertex list.
struct ObjModel {
    struct Part {
        std::shared_ptr<const Mesh> mesh;
        int material = -1;  ///< index into materials; -1: none
    };
    std::vector<Part> parts;
    std::vector<ObjMaterial> materials;
    std::string mtl_path;  ///< the library read (empty: the file names none)
};

/// Reads an OBJ file and the material library its first `mtllib` line names (relative to
/// the OBJ file's folder; read with tinyobjloader). A part keeps its texture coordinates when
/// `with_uv` or its material has map_Kd. Throws std::runtime_error like load_obj_mesh, and for
/// a library that cannot be read.
ObjModel load_obj_model(const std::string& path, bool with_uv);

// ---- generated surfaces (tests, benchmarks, the sample scene) -----------------------------

/// Vertices and triangles of a generated surface.
struct MeshData {
    std::vector<float> positions;
    std::vector<std::uint32_t> triangles;
};

/// The unit sphere as a UV sphere: `rings` bands of latitude, `segments` of longitude, all
/// vertices on the sphere, shared (closed, no cracks by construction), poles single vertices.
MeshData uv_sphere(int rings, int segments);
/// The unit sphere as a subdivided icosahedron (20 * 4^level triangles), vertices on it.
MeshData icosphere(int level);
/// The cube [-1,1]^3, each face an n x n grid of quads cut into two triangles, closed.
MeshData cube_mesh(int n);
/// Writes positions and triangles as an OBJ file (v / f lines, 1-based); false on failure.
bool write_obj(const std::string& path, const MeshData& m);

}  // namespace streamrt
