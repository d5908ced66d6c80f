#pragma once
// The plain view of a mesh (engine/mesh/mesh.h) that kernels read.
#include <cstddef>
#include <cstdint>

#include "accel/bvh.h"

namespace streamrt {

/// Triangles tested together against one ray by the single-ray mesh walk
/// (kernels/mesh_single_kernel.h): one SIMD lane each.
inline constexpr int kBlockTriangles = 4;

/// kBlockTriangles triangles of one leaf as structure-of-arrays: corner[c][axis][lane]. A
/// leaf of n triangles owns ceil(n / 4) consecutive blocks; unused lanes hold NaN corners,
/// which the watertight test never accepts (every comparison with NaN is false, so t > 0
/// fails) and which never trigger its exact fallback (NaN == 0 is false).
struct alignas(16) TriangleBlock {
    float corner[3][3][kBlockTriangles];
};
static_assert(sizeof(TriangleBlock) == 144);

/// What the kernels and the renderers read of a mesh: raw pointers only (see
/// kernels/shade_job.h on why the per-ISA files touch no container code). Triangles are in
/// the BVH's leaf order: a leaf (first, count) holds triangles first .. first + count - 1.
struct MeshView {
    const accel::WideNode* nodes;    ///< the mesh BVH, nullptr when it has no triangles
    const float* positions;          ///< 3 floats per vertex (triangle_corner)
    const std::uint32_t* index;      ///< 3 vertex numbers per triangle (into positions and normals)
    const float* vertex_normals;     ///< 3 floats per vertex, unit (area-weighted face normals)
    std::uint32_t n_tris;
    /// Texture coordinates (OBJ vt), 6 floats per triangle (u, v at its corners 0, 1, 2),
    /// leaf order; nullptr when the mesh was read without them (no textured object uses it).
    const float* uv = nullptr;
    /// How fast (u, v) changes per canonical unit along the surface (the mesh's total uv
    /// edge length over its total edge length), for the mip level selection.
    float uv_density = 1.f;
    /// The leaves' triangles as blocks, for the single-ray walk; block_of[first] is the first
    /// block of the leaf whose first triangle is `first` (other entries unused).
    const TriangleBlock* blocks = nullptr;
    const std::uint32_t* block_of = nullptr;
    /// Hybrid walk: a packet continues as single rays (one walk per lane) from any stack
    /// entry that at most this many of its lanes reached (0: packet only; the packet width or
    /// more: single rays from the root). Measured in docs/performance.md "### Meshes".
    std::uint32_t single_ray_lanes = 0;
    /// The mesh's triangles and nodes outgrow a core's share of the caches (kPrefetchedMeshBytes):
    /// the packet walks then start loading each child they will visit when they meet it.
    bool prefetched = false;
    /// Colours at the vertices (linear RGB, 3 floats per vertex, indexed like vertex_normals);
    /// nullptr when the mesh was read without them (no vertex_colors=true object uses it).
    const float* vertex_colors = nullptr;
};

/// Corner j (0 - 2) of triangle k: its vertex's 3 coordinates. Triangles are held as vertex
/// numbers into the shared positions, not as 9 floats each: 12 + 12 / 2 bytes a triangle on a
/// closed mesh instead of 36, and the walks read the same floats (docs/performance.md,
/// "Memory per vertex and triangle").
inline const float* triangle_corner(const MeshView& m, std::size_t k, int j) {
    return m.positions + 3 * std::size_t(m.index[3 * k + std::size_t(j)]);
}

/// Positions, vertex numbers and BVH nodes above which a mesh is walked with prefetches (MeshView::prefetched):
/// half of this machine class's 4 MiB L2 per core, the rest for the rays and other meshes.
/// Measured (docs/performance.md, "The closest walk on large meshes"): on shadow rays the prefetch
/// gains 5 - 14 % on the 235k-triangle and larger meshes and costs the 3.7k-triangle bunny's.
inline constexpr std::size_t kPrefetchedMeshBytes = std::size_t(2) << 20;

}  // namespace streamrt
