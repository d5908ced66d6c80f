#pragma once
// Whole-stream traversal of a mesh (perf/stream_walk_avx512.cpp), for measuring it against the
// engine's packet and single-ray walks (perf/stream_walk_bench.cpp). Not a test, not used by
// the renderer.
#include <cstddef>
#include <cstdint>

#include "mesh/mesh_view.h"

namespace streamrt::perf {

/// A stream of rays in the mesh's space, structure of arrays, and what the walk finds: for a
/// closest-hit walk t shrinks to the nearest hit and prim/u/v receive it (prim -1: no hit);
/// for an any-hit walk blocked[i] becomes 1 where the mesh blocks ray i within (0, t).
struct StreamRays {
    const float *ox, *oy, *oz, *dx, *dy, *dz;
    std::size_t count;
    float* t;
    std::int32_t* prim;
    float *u, *v;
    std::uint8_t* blocked;
};

/// Counters of one walk (nodes visited, rays tested against a node's children, rays tested
/// against a leaf's triangles).
struct StreamWalkStats {
    std::size_t nodes = 0, node_rays = 0, leaf_rays = 0;
};

/// Traces the whole stream through the mesh's tree at once: every node is visited once with
/// the list of the rays that reached it, which is filtered against its 8 children (16 rays per
/// test) into one list per child; the lists are walked depth first, the child nearest along the
/// list's first ray first. AVX-512 only (stream_walk_supported()).
StreamWalkStats stream_walk(const MeshView& m, const StreamRays& rays, bool any);
bool stream_walk_supported();

}  // namespace streamrt::perf
