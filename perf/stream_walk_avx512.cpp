// Whole-stream traversal (perf/stream_walk.h), built with the AVX-512 flags of the kernels
// (engine/kernels/isa_flags.cmake). The box and triangle tests are the engine's own
// (kernels/mesh_kernel.h: robust_box, the watertight test through LanePermutedTriangles, the
// tie rule), so the walk finds the engine's hits bit for bit; only the order of the work differs.
#define STREAMRT_ISA_NAMESPACE perf_avx512
#include "kernels/mesh_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <vector>

#include "stream_walk.h"

namespace streamrt::perf {

namespace {

using B = xsimd::batch<float, xsimd::avx512bw>;
using I = xsimd::batch<std::int32_t, xsimd::avx512bw>;
constexpr int W = 16;

struct Walker {
    const MeshView& m;
    const StreamRays& r;
    bool any;
    std::vector<float> ix, iy, iz;   ///< 1 / direction, per ray
    std::vector<std::uint32_t> pool;  ///< ray lists, a stack: a node's children's lists above its own
    StreamWalkStats stats;

    /// Rays idx[k .. k + 16) of a list of n (lanes past n inactive: t = -1, which meets no box).
    struct Batch {
        __m512i idx;
        __mmask16 live;
        Vec3T<B> o, d, inv;
        B t;
    };
    Batch load(const std::uint32_t* idx, std::size_t k, std::size_t n) const {
        Batch b;
        b.live = n - k >= W ? __mmask16(0xffff) : __mmask16((1u << (n - k)) - 1);
        b.idx = _mm512_maskz_loadu_epi32(b.live, idx + k);
        const auto g = [&](const float* a, float fill) {
            return B(_mm512_mask_i32gather_ps(_mm512_set1_ps(fill), b.live, b.idx, a, 4));
        };
        b.o = {g(r.ox, 0.f), g(r.oy, 0.f), g(r.oz, 0.f)};
        b.d = {g(r.dx, 0.f), g(r.dy, 0.f), g(r.dz, 1.f)};
        b.inv = {g(ix.data(), 0.f), g(iy.data(), 0.f), g(iz.data(), 1.f)};
        b.t = g(r.t, -1.f);
        return b;
    }

    void leaf(std::int32_t first, std::uint32_t count, std::size_t at, std::size_t n) {
        stats.leaf_rays += n;
        const std::uint32_t* idx = pool.data() + at;
        for (std::size_t k = 0; k < n; k += W) {
            Batch b = load(idx, k, n);
            const WatertightRay<B> wr = watertight_ray(b.o, b.d);
            const mesh_detail::LanePermutedTriangles<B> corners(wr, b.o);
            if (any) {
                auto open = b.t > B(0.f);
                auto blocked = B(0.f) != B(0.f);
                for (std::uint32_t j = 0; j < count; ++j) {
                    const auto now = open && triangle_blocks_sheared(corners.sheared(wr, m, std::uint32_t(first) + j), b.t);
                    blocked = blocked || now;
                    open = open && !now;
                }
                const __mmask16 hit = __mmask16(movemask_bits(blocked));
                // A blocked ray's t becomes -1: it meets no box after this.
                _mm512_mask_i32scatter_ps(r.t, hit, b.idx, _mm512_set1_ps(-1.f), 4);
                for (std::uint32_t bits = hit; bits; bits &= bits - 1)
                    r.blocked[idx[k + std::size_t(std::countr_zero(bits))]] = 1;
                continue;
            }
            B best = b.t, bu(0.f), bv(0.f);
            I bprim = I(_mm512_mask_i32gather_epi32(_mm512_set1_epi32(-1), b.live, b.idx, r.prim, 4));
            for (std::uint32_t j = 0; j < count; ++j) {
                const std::uint32_t tri = std::uint32_t(first) + j;
                const auto sheared = corners.sheared(wr, m, tri);
                if (!xsimd::any(triangle_may_hit(sheared, best))) continue;
                const TriangleHit<B> h = triangle_hit_sheared<true>(sheared, B(0.f), best);
                const auto closer = h.t < best || (h.t == best && xsimd::bool_cast(I(std::int32_t(tri)) < bprim));
                best = xsimd::select(closer, h.t, best);
                bu = xsimd::select(closer, h.u, bu);
                bv = xsimd::select(closer, h.v, bv);
                bprim = xsimd::select(xsimd::bool_cast(closer), I(std::int32_t(tri)), bprim);
            }
            const __mmask16 better = __mmask16(movemask_bits(best < b.t)) & b.live;
            _mm512_mask_i32scatter_ps(r.t, better, b.idx, best, 4);
            _mm512_mask_i32scatter_ps(r.u, better, b.idx, bu, 4);
            _mm512_mask_i32scatter_ps(r.v, better, b.idx, bv, 4);
            _mm512_mask_i32scatter_epi32(r.prim, better, b.idx, bprim, 4);
        }
    }

    /// Visits node `index` with the list pool[at .. at + n); pool[free ..) is unused.
    void node(std::int32_t index, std::size_t at, std::size_t n, std::size_t free) {
        ++stats.nodes;
        stats.node_rays += n;
        const accel::WideNode& nd = m.nodes[index];
        int kids = 0;
        while (kids < accel::kNodeWidth && nd.child[kids] >= 0) ++kids;
        // One list per child from `free` on, each with room for every ray of this one.
        if (pool.size() < free + std::size_t(kids) * n) pool.resize(free + std::size_t(kids) * n + (1u << 16));
        std::size_t len[accel::kNodeWidth] = {};
        for (std::size_t k = 0; k < n; k += W) {
            const Batch b = load(pool.data() + at, k, n);
            for (int j = 0; j < kids; ++j) {
                B tn;
                const __mmask16 hit =
                    __mmask16(movemask_bits(mesh_detail::robust_box(nd, j, b.o, b.inv, b.t, tn))) & b.live;
                _mm512_mask_compressstoreu_epi32(pool.data() + free + std::size_t(j) * n + len[j], hit, b.idx);
                len[j] += std::size_t(std::popcount(unsigned(hit)));
            }
        }
        // Nearest child first along the list's first ray (its box centre's distance).
        const std::uint32_t first = pool[at];
        const float fx = r.dx[first], fy = r.dy[first], fz = r.dz[first];
        int order[accel::kNodeWidth];
        float key[accel::kNodeWidth];
        for (int j = 0; j < kids; ++j) {
            order[j] = j;
            key[j] = fx * (nd.lo_x[j] + nd.hi_x[j]) + fy * (nd.lo_y[j] + nd.hi_y[j]) + fz * (nd.lo_z[j] + nd.hi_z[j]);
        }
        std::sort(order, order + kids, [&](int a, int b) { return key[a] < key[b]; });
        const std::size_t deeper = free + std::size_t(kids) * n;
        for (int q = 0; q < kids; ++q) {
            const int j = order[q];
            if (len[j] == 0) continue;
            const std::size_t list = free + std::size_t(j) * n;
            if (nd.count[j] > 0) leaf(nd.child[j], nd.count[j], list, len[j]);
            else node(nd.child[j], list, len[j], deeper);
        }
    }
};

}  // namespace

bool stream_walk_supported() { return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw"); }

StreamWalkStats stream_walk(const MeshView& m, const StreamRays& r, bool any) {
    Walker w{m, r, any, {}, {}, {}, {}, {}};
    if (!m.nodes || r.count == 0) return w.stats;
    w.ix.resize(r.count), w.iy.resize(r.count), w.iz.resize(r.count);
    w.pool.reserve(16 * r.count);
    for (std::size_t i = 0; i < r.count; ++i) {
        w.ix[i] = 1.f / r.dx[i], w.iy[i] = 1.f / r.dy[i], w.iz[i] = 1.f / r.dz[i];
        if (r.t[i] > 0.f) w.pool.push_back(std::uint32_t(i));
    }
    const std::size_t n = w.pool.size();
    if (n > 0) w.node(0, 0, n, n);
    return w.stats;
}

}  // namespace streamrt::perf
