// Whole-stream traversal (perf/stream_walk.h) through the engine's own walk
// (kernels/mesh_stream_kernel.h), built with the AVX-512 flags of the kernels
// (engine/kernels/isa_flags.cmake), under a namespace of its own (simd/isa_namespace.h).
#define STREAMRT_ISA_NAMESPACE perf_avx512
#include "kernels/mesh_kernel.h"

#include "stream_walk.h"

namespace streamrt::perf {

StreamWalkStats stream_walk(const MeshView& m, const StreamRays& r, bool any) {
    using namespace perf_avx512::mesh_detail;
    static thread_local RawBuffer<std::uint32_t> list, pool;
    static thread_local RawBuffer<float> inverse;
    std::size_t n = 0;
    std::uint32_t* l = list.reserve(r.count);
    for (std::size_t i = 0; i < r.count; ++i)
        if (r.t[i] > 0.f) l[n++] = std::uint32_t(i);
    const StreamWalkRays rays{r.ox, r.oy, r.oz, r.dx, r.dy, r.dz, r.t, r.prim, r.u, r.v, any ? r.blocked : nullptr};
    const StreamWalkCounts c = StreamWalker(m, rays, inverse, pool, r.count).walk(l, n);
    return {c.nodes, c.node_rays, c.leaf_rays};
}

}  // namespace streamrt::perf
