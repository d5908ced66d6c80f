#pragma once
// The whole-stream mesh walk (AVX-512 only): a list of rays walks a mesh's 8-wide BVH at once.
// Each node is visited once with the list of the rays that reached it, filtered 16 rays at a
// time (their data gathered) against the node's child boxes into one list per child
// (compress-stores); the lists are walked depth first, the child nearest along the list's first
// ray first; a leaf tests its triangles against its list 16 rays at a time. The box test, the
// watertight triangle test and the tie rule are the packet walk's (mesh_kernel.h), so every ray
// gets the packet walk's hit to the bit, whatever the order of the work. It pays where rays have
// lost their coherence and come by the hundred: the deep rays of a glass mesh
// (docs/performance.md, "Whole streams through the tree"). Raw buffers only: the per-level
// files touch no container code (intersect_kernel.h). Included by kernels/mesh_kernel.h.
#if defined(__AVX512F__) && defined(__AVX512BW__)
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <new>

namespace streamrt::STREAMRT_ISA_NAMESPACE {

namespace mesh_detail {

/// The rays of a stream walk, structure of arrays indexed by ray number, in the mesh's space.
/// Closest hits: t is the best distance so far, shrunk where the walk finds a closer hit;
/// prim/u/v receive the hit (prim -1 before the walk: a tie at t with another object's hit
/// keeps that one, as in the packet walk). Any hits (`blocked` set): blocked[i] becomes 1 and
/// t[i] -1 where the mesh blocks ray i within (0, t[i]).
struct StreamWalkRays {
    const float *ox, *oy, *oz, *dx, *dy, *dz;
    float* t;
    std::int32_t* prim = nullptr;
    float *u = nullptr, *v = nullptr;
    std::uint8_t* blocked = nullptr;
};

/// Counters of a walk: nodes visited, rays tested against a node's children, rays tested
/// against leaves.
struct StreamWalkCounts {
    std::size_t nodes = 0, node_rays = 0, leaf_rays = 0;
};

/// A growable buffer of T from malloc (no container code in the kernel files); one per thread.
template <class T>
struct RawBuffer {
    T* data = nullptr;
    std::size_t size = 0;
    ~RawBuffer() { std::free(data); }
    /// Room for n; the contents up to the old size are kept.
    T* reserve(std::size_t n) {
        if (n > size) {
            const std::size_t grown = std::max(n, size + size / 2);
            T* p = static_cast<T*>(std::realloc(data, grown * sizeof(T)));
            if (!p) throw std::bad_alloc();
            data = p, size = grown;
        }
        return data;
    }
};

class StreamWalker {
  public:
    using B = xsimd::batch<float, xsimd::avx512bw>;
    using I = xsimd::batch<std::int32_t, xsimd::avx512bw>;
    static constexpr std::size_t W = 16;

    StreamWalker(const MeshView& m, const StreamWalkRays& r, RawBuffer<float>& inverse, RawBuffer<std::uint32_t>& pool,
                 std::size_t n_rays)
        : m_(m), r_(r), pool_(pool) {
        // 1 / direction of every ray the lists may name (ray numbers below n_rays).
        float* inv = inverse.reserve(3 * n_rays);
        ix_ = inv, iy_ = inv + n_rays, iz_ = inv + 2 * n_rays;
    }

    /// Walks the rays list[0 .. n) (ray numbers, each at most once) from the root.
    StreamWalkCounts walk(const std::uint32_t* list, std::size_t n) {
        for (std::size_t k = 0; k < n; ++k) {
            const std::uint32_t i = list[k];
            ix_[i] = 1.f / r_.dx[i], iy_[i] = 1.f / r_.dy[i], iz_[i] = 1.f / r_.dz[i];
        }
        std::copy_n(list, n, pool_.reserve(n));
        if (n > 0 && m_.nodes) node(0, 0, n, n);
        return counts_;
    }

  private:
    /// Rays list[k .. k + 16) of a list of n (lanes past n inactive: t = -1 meets no box).
    struct Batch {
        __m512i idx;
        __mmask16 live;
        Vec3T<B> o, d, inv;
        B t;
    };
    Batch load(const std::uint32_t* list, std::size_t k, std::size_t n) const {
        Batch b;
        b.live = n - k >= W ? __mmask16(0xffff) : __mmask16((1u << (n - k)) - 1);
        b.idx = _mm512_maskz_loadu_epi32(b.live, list + k);
        const auto g = [&](const float* a, float fill) {
            return B(_mm512_mask_i32gather_ps(_mm512_set1_ps(fill), b.live, b.idx, a, 4));
        };
        b.o = {g(r_.ox, 0.f), g(r_.oy, 0.f), g(r_.oz, 0.f)};
        b.d = {g(r_.dx, 0.f), g(r_.dy, 0.f), g(r_.dz, 1.f)};
        b.inv = {g(ix_, 0.f), g(iy_, 0.f), g(iz_, 1.f)};
        b.t = g(r_.t, -1.f);
        return b;
    }

    /// The leaf's triangles [first, first + count) against the list pool[at .. at + n).
    void leaf(std::uint32_t first, std::uint32_t count, std::size_t at, std::size_t n) {
        counts_.leaf_rays += n;
        const std::uint32_t* list = pool_.data + at;
        for (std::size_t k = 0; k < n; k += W) {
            const Batch b = load(list, k, n);
            const WatertightRay<B> wr = watertight_ray(b.o, b.d);
            const LanePermutedTriangles<B> corners(wr, b.o);
            if (r_.blocked) {
                auto open = b.t > B(0.f);
                for (std::uint32_t j = 0; j < count && xsimd::any(open); ++j)
                    open = open && !triangle_blocks_sheared(corners.sheared(wr, m_, first + j), b.t);
                const __mmask16 hit = __mmask16(movemask_bits(b.t > B(0.f) && !open)) & b.live;
                // A blocked ray's t becomes -1: it meets no box after this.
                _mm512_mask_i32scatter_ps(r_.t, hit, b.idx, _mm512_set1_ps(-1.f), 4);
                for (std::uint32_t bits = hit; bits; bits &= bits - 1) r_.blocked[list[k + std::size_t(std::countr_zero(bits))]] = 1;
                continue;
            }
            const I prim_before(_mm512_mask_i32gather_epi32(_mm512_set1_epi32(-1), b.live, b.idx, r_.prim, 4));
            B best = b.t, bu(0.f), bv(0.f);
            I bprim = prim_before;
            for (std::uint32_t j = 0; j < count; ++j) {
                const std::uint32_t tri = first + j;
                const auto sheared = corners.sheared(wr, m_, tri);
                if (!xsimd::any(triangle_may_hit(sheared, best))) continue;
                const TriangleHit<B> h = triangle_hit_sheared<true>(sheared, B(0.f), best);
                // The packet walk's tie rule: at one t the lower triangle number.
                const auto closer = h.t < best || (h.t == best && xsimd::bool_cast(I(std::int32_t(tri)) < bprim));
                best = xsimd::select(closer, h.t, best);
                bu = xsimd::select(closer, h.u, bu);
                bv = xsimd::select(closer, h.v, bv);
                bprim = xsimd::select(xsimd::bool_cast(closer), I(std::int32_t(tri)), bprim);
            }
            const __mmask16 changed = __mmask16(movemask_bits(xsimd::bool_cast(bprim != prim_before))) & b.live;
            if (!changed) continue;
            _mm512_mask_i32scatter_ps(r_.t, changed, b.idx, best, 4);
            _mm512_mask_i32scatter_ps(r_.u, changed, b.idx, bu, 4);
            _mm512_mask_i32scatter_ps(r_.v, changed, b.idx, bv, 4);
            _mm512_mask_i32scatter_epi32(r_.prim, changed, b.idx, bprim, 4);
        }
    }

    /// Node `index` with the list pool[at .. at + n); pool[free ..) is unused.
    void node(std::int32_t index, std::size_t at, std::size_t n, std::size_t free) {
        ++counts_.nodes;
        counts_.node_rays += n;
        const accel::WideNode& nd = m_.nodes[index];
        int kids = 0;
        while (kids < accel::kNodeWidth && nd.child[kids] >= 0) ++kids;
        // One list per child from `free` on, each with room for every ray of this one (the
        // memory check bounds the lists of a path down the tree: kernels/stream_walk_memory.h).
        pool_.reserve(free + std::size_t(kids) * n);
        std::size_t len[accel::kNodeWidth] = {};
        for (std::size_t k = 0; k < n; k += W) {
            const Batch b = load(pool_.data + at, k, n);
            for (int j = 0; j < kids; ++j) {
                B tn;
                const __mmask16 hit = __mmask16(movemask_bits(robust_box(nd, j, b.o, b.inv, b.t, tn))) & b.live;
                _mm512_mask_compressstoreu_epi32(pool_.data + free + std::size_t(j) * n + len[j], hit, b.idx);
                len[j] += std::size_t(std::popcount(unsigned(hit)));
            }
        }
        // Nearest child first along the list's first ray (its box centre's distance).
        const std::uint32_t lead = pool_.data[at];
        const float fx = r_.dx[lead], fy = r_.dy[lead], fz = r_.dz[lead];
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
            if (nd.count[j] > 0) leaf(std::uint32_t(nd.child[j]), nd.count[j], list, len[j]);
            else node(nd.child[j], list, len[j], deeper);
        }
    }

    const MeshView& m_;
    const StreamWalkRays& r_;
    RawBuffer<std::uint32_t>& pool_;
    float *ix_, *iy_, *iz_;
    StreamWalkCounts counts_;
};

}  // namespace mesh_detail

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
#endif
