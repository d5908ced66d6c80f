#pragma once
// The plain view of a mesh (engine/mesh/mesh.h) that kernels read.
#include <cstdint>

#include "accel/bvh.h"

namespace streamrt {

/// What the kernels and the renderers read of a mesh: raw pointers only (see
/// kernels/shade_job.h on why the per-ISA files touch no container code). Triangles are in
/// the BVH's leaf order: a leaf (first, count) holds triangles first .. first + count - 1.
struct MeshView {
    const accel::WideNode* nodes;    ///< the mesh BVH, nullptr when it has no triangles
    const float* tri;                ///< 9 floats per triangle: p0, p1, p2
    const std::uint32_t* index;      ///< 3 vertex numbers per triangle (into normals)
    const float* vertex_normals;     ///< 3 floats per vertex, unit (area-weighted face normals)
    std::uint32_t n_tris;
    /// Texture coordinates (OBJ vt), 6 floats per triangle (u, v at its corners 0, 1, 2),
    /// leaf order; nullptr when the mesh was read without them (no textured object uses it).
    const float* uv = nullptr;
    /// How fast (u, v) changes per canonical unit along the surface (the mesh's total uv
    /// edge length over its total edge length), for the mip level selection.
    float uv_density = 1.f;
};

}  // namespace streamrt
