#pragma once
// The single-ray mesh walk: one ray (in the mesh's canonical space) walks the mesh's 8-wide
// BVH alone. A node's 8 child boxes are tested in one 8-lane slab test (two 4-lane halves on
// the SSE levels), a leaf's triangles 4 at a time from their structure-of-arrays blocks
// (MeshView::blocks), with the watertight test of shapes/triangle_math.h run with triangles
// in the lanes instead of rays. Incoherent rays (shadow, mirror, glass) gain from it; the
// packet walk (mesh_kernel.h) hands them over when few lanes of a packet remain.
// Included only by kernels/isa_*.cpp, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <immintrin.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "mesh/mesh_view.h"
#include "shapes/triangle_math.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

namespace mesh_detail {

constexpr int kStack = accel::kNodeWidth * 64;
constexpr float kInf = std::numeric_limits<float>::infinity();
/// 1 + 2 gamma(3): a box's far distance is widened by this (Ize 2013, "Robust BVH ray
/// traversal"), so float rounding in the slabs never drops a box the ray touches.
constexpr float kWiden = 1.f + 2.f * (3.f * 0x1p-24f) / (1.f - 3.f * 0x1p-24f);

struct Entry {
    std::int32_t child;
    std::uint32_t count;
    float t;  ///< entry distance into the box (the smallest over the lanes for a packet)
};

}  // namespace mesh_detail

/// The arches of the single-ray walk for a level's packet arch: nodes take 8 lanes (AVX2
/// registers on the AVX levels, two halves of 4 on SSE), leaves 4 (one per block triangle).
template <class Arch, bool Wide = (xsimd::batch<float, Arch>::size >= 8)>
struct SingleRayArchs {
    using node = Arch;
    using leaf = Arch;
};
template <class Arch>
struct SingleRayArchs<Arch, true> {
    using node = xsimd::fma3<xsimd::avx2>;
    using leaf = xsimd::sse4_2;
};

/// A mesh hit of one ray: triangle number and barycentrics (TriangleHit's u, v).
struct MeshHit {
    std::int32_t prim = -1;
    float u = 0.f, v = 0.f;
};

/// One ray set up for the walk: per axis the offset (in floats from the node's start) of the
/// near and far planes, chosen once from the direction's signs (the slab test then needs no
/// min/max), and the watertight test's per-ray constants with its axis permutation as
/// indices (the leaf loads permuted coordinates directly).
template <class NodeArch, class LeafArch>
struct SingleRay {
    using NB = xsimd::batch<float, NodeArch>;
    using LB = xsimd::batch<float, LeafArch>;
    static_assert(LB::size == std::size_t(kBlockTriangles), "a leaf block is one triangle per lane");
    NB ox, oy, oz, ix, iy, iz;
    int near[3], far[3];
    int axis[3];  ///< kx, ky, kz of the watertight test
    LB o_perm[3];  ///< origin's coordinates on those axes
    WatertightRay<LB> wr;  ///< sx, sy, sz used (the permutation masks are axis[] here)

    SingleRay(const Vec3f& o, const Vec3f& d) : ox(o.x), oy(o.y), oz(o.z), ix(1.f / d.x), iy(1.f / d.y), iz(1.f / d.z) {
        const float inv[3] = {1.f / d.x, 1.f / d.y, 1.f / d.z};
        for (int a = 0; a < 3; ++a) {
            // WideNode: lo_x, lo_y, lo_z, hi_x, hi_y, hi_z, 8 floats each. A negative
            // direction (-0 included: 1 / -0 = -inf) enters through the high plane.
            const int lo = a * accel::kNodeWidth, hi = (3 + a) * accel::kNodeWidth;
            near[a] = inv[a] < 0.f ? hi : lo;
            far[a] = inv[a] < 0.f ? lo : hi;
        }
        const WatertightRay<float> w = watertight_ray(o, d);  // the per-lane setup, once
        axis[0] = w.kx0 ? 0 : w.kx1 ? 1 : 2;
        axis[1] = w.ky0 ? 0 : w.ky1 ? 1 : 2;
        axis[2] = w.kz0 ? 0 : w.kz1 ? 1 : 2;
        const float oc[3] = {o.x, o.y, o.z};
        for (int a = 0; a < 3; ++a) o_perm[a] = LB(oc[axis[a]]);
        wr.sx = LB(w.sx);
        wr.sy = LB(w.sy);
        wr.sz = LB(w.sz);
    }
};

/// Bit l set where lane l of the mask is true, with the movemask instruction (compress.h's
/// lane_bits goes through memory).
template <class A>
inline std::uint32_t movemask_bits(const xsimd::batch_bool<float, A>& m) {
    using M = xsimd::batch_bool<float, A>;
    // AVX-512: a mask register (an integer of at most 8 bytes; SSE/AVX registers are 16 or 32).
    // sizeof rather than is_integral<register_type>: a vector type as a template argument
    // loses its alignment attribute, and GCC warns.
    if constexpr (sizeof(typename M::register_type) <= sizeof(std::uint64_t)) {
        return std::uint32_t(typename M::register_type(m));
    } else if constexpr (M::size == 8) {
        return std::uint32_t(_mm256_movemask_ps(typename M::register_type(m)));
    } else {
        static_assert(M::size == 4);
        return std::uint32_t(_mm_movemask_ps(typename M::register_type(m)));
    }
}

/// The mask whose lane l is true where bit l of `bits` is set (movemask_bits' inverse).
template <class A>
inline xsimd::batch_bool<float, A> mask_from_bits(std::uint32_t bits) {
    using M = xsimd::batch_bool<float, A>;
    if constexpr (sizeof(typename M::register_type) <= sizeof(std::uint64_t)) {
        return M(typename M::register_type(bits));
    } else {
        using I = xsimd::batch<std::int32_t, A>;
        alignas(64) std::int32_t bit[M::size];
        for (std::size_t l = 0; l < M::size; ++l) bit[l] = std::int32_t(1u << l);
        const I b = I::load_aligned(bit);
        return xsimd::bool_cast((I(std::int32_t(bits)) & b) != I(0));
    }
}

namespace mesh_detail {

/// Starts loading a child the single-ray walk will visit: an inner node's boxes (the first
/// 192 of its 256 bytes) or a leaf's first block (144 bytes). The walk is a chain of dependent
/// loads (pop, node, child, leaf), so without this it waits on memory at every step. (The
/// packet walks prefetch too, but only on meshes larger than the caches, MeshView::prefetched.)
inline void prefetch_child(const MeshView& m, const Entry& e) {
    const void* p = e.count == 0 ? static_cast<const void*>(m.nodes + e.child)
                                 : static_cast<const void*>(m.blocks + m.block_of[e.child]);
    simd::prefetch_lines(p, 192);
}

/// The children of node n the ray enters with t in [0, t_max] (far distance widened by
/// kWiden; boxes are conservative, accel::conservative_box): written to hits[] nearest
/// last, so pushing them in order pops the nearest first. A NaN slab distance (0 * inf: the
/// ray lies in a slab plane) does not limit the interval, so such a ray is kept. An empty
/// child slot (lo = +inf, hi = -inf) fails the test for any ray with a finite or infinite
/// origin; a NaN origin would pass it, hence the check of its child number. Inlined into the
/// walk, so the ray's constants stay in registers from node to node.
template <class NodeArch, class LeafArch>
[[gnu::always_inline]] inline int single_node_hits(const MeshView& m, const accel::WideNode& n,
                                                   const SingleRay<NodeArch, LeafArch>& r, float t_max, Entry* hits) {
    using NB = typename SingleRay<NodeArch, LeafArch>::NB;
    constexpr std::size_t NW = NB::size;
    const float* base = reinterpret_cast<const float*>(&n);
    alignas(32) float t_out[accel::kNodeWidth];
    std::uint32_t hit_bits = 0;
    for (std::size_t j = 0; j < std::size_t(accel::kNodeWidth); j += NW) {
        NB tn(0.f), tf(t_max);
        const auto axis = [&](int a, const NB& oc, const NB& ic) {
            const NB n_a = (NB::load_aligned(base + r.near[a] + j) - oc) * ic;
            const NB f_a = (NB::load_aligned(base + r.far[a] + j) - oc) * ic;
            // max(x, y) and min(x, y) are the maxps / minps instructions, which give y when x
            // is NaN: select(n_a > tn, n_a, tn) to the bit, one instruction instead of a
            // compare and a blend on the walk's critical path.
            tn = xsimd::max(n_a, tn);
            tf = xsimd::min(f_a, tf);
        };
        axis(0, r.ox, r.ix);
        axis(1, r.oy, r.iy);
        axis(2, r.oz, r.iz);
        tn.store_aligned(t_out + j);
        hit_bits |= movemask_bits(tn <= tf * NB(kWiden)) << j;
    }
    int nh = 0;
    for (; hit_bits; hit_bits &= hit_bits - 1) {
        const int j = std::countr_zero(hit_bits);
        if (n.child[j] < 0) continue;
        const Entry e{n.child[j], n.count[j], t_out[j]};
        prefetch_child(m, e);
        int k = nh++;
        while (k > 0 && hits[k - 1].t < e.t) {  // farthest first
            hits[k] = hits[k - 1];
            --k;
        }
        hits[k] = e;
    }
    return nh;
}

/// Corner c of a block's 4 triangles relative to the ray's origin, on the ray's permuted axes.
template <class NodeArch, class LeafArch>
inline auto block_corner(const TriangleBlock& b, int c, const SingleRay<NodeArch, LeafArch>& r) {
    using LB = typename SingleRay<NodeArch, LeafArch>::LB;
    return Vec3T<LB>{LB::load_aligned(b.corner[c][r.axis[0]]) - r.o_perm[0],
                     LB::load_aligned(b.corner[c][r.axis[1]]) - r.o_perm[1],
                     LB::load_aligned(b.corner[c][r.axis[2]]) - r.o_perm[2]};
}

/// The leaf (first, count) against one ray, 4 triangles per test: shrinks best and records
/// the hit; true when it found one.
template <class NodeArch, class LeafArch>
inline bool single_leaf_closest(const MeshView& m, const SingleRay<NodeArch, LeafArch>& r, std::uint32_t first,
                                std::uint32_t count, float& best, MeshHit& hit) {
    using LB = typename SingleRay<NodeArch, LeafArch>::LB;
    const TriangleBlock* b = m.blocks + m.block_of[first];
    bool found = false;
    for (std::uint32_t k = 0; k < count; k += kBlockTriangles, ++b) {
        const auto sheared =
            tri_detail::shear(r.wr, block_corner(*b, 0, r), block_corner(*b, 1, r), block_corner(*b, 2, r));
        if (!xsimd::any(triangle_may_hit(sheared, LB(best)))) continue;
        const TriangleHit<LB> h = triangle_hit_sheared<true>(sheared, LB(0.f), LB(best));
        if (!xsimd::any(h.t <= LB(best))) continue;
        alignas(16) float t[kBlockTriangles], u[kBlockTriangles], v[kBlockTriangles];
        h.t.store_aligned(t);
        h.u.store_aligned(u);
        h.v.store_aligned(v);
        for (int l = 0; l < kBlockTriangles; ++l) {
            // A tie goes to the lower triangle number (mesh_kernel.h's packet walk): the hit
            // does not depend on the order of the walk.
            const std::int32_t prim = std::int32_t(first + k + std::uint32_t(l));
            if (t[l] < best || (t[l] == best && prim < hit.prim)) {
                best = t[l];
                hit = {prim, u[l], v[l]};
                found = true;
            }
        }
    }
    return found;
}

template <class NodeArch, class LeafArch>
inline bool single_leaf_any(const MeshView& m, const SingleRay<NodeArch, LeafArch>& r, std::uint32_t first,
                            std::uint32_t count, float t_max) {
    using LB = typename SingleRay<NodeArch, LeafArch>::LB;
    const TriangleBlock* b = m.blocks + m.block_of[first];
    for (std::uint32_t k = 0; k < count; k += kBlockTriangles, ++b)
        if (xsimd::any(triangle_blocks_permuted(r.wr, block_corner(*b, 0, r), block_corner(*b, 1, r),
                                                block_corner(*b, 2, r), LB(t_max))))
            return true;
    return false;
}

/// One step of a walk, front to back: visits the entry e (a node or a leaf) and moves e to the
/// next, popping from stack[0 .. sp). leaf(first, count) tests a leaf and returns true to
/// stop; t_max (which the leaf may shrink) bounds the boxes, and a pop entered beyond it is
/// skipped. False when the walk is over. The walk's position (e, sp, stack) belongs to the
/// caller as local variables: kept in a struct, e and sp lived in memory beside the stack
/// the step writes, and the any-hit walk lost 12 - 15 % (measured).
template <class NodeArch, class LeafArch, class Leaf>
[[gnu::always_inline]] inline bool walk_step(const MeshView& m, const SingleRay<NodeArch, LeafArch>& r,
                                             const float& t_max, Leaf&& leaf, Entry& e, int& sp, Entry* stack) {
    if (e.count > 0) {
        if (leaf(std::uint32_t(e.child), e.count)) return false;
    } else if (const int nh = single_node_hits(m, m.nodes[e.child], r, t_max, stack + sp); nh > 0) {
        // The nearest child is the last one written: visit it now (its entry is within
        // t_max), the others stay pushed.
        sp += nh - 1;
        e = stack[sp];
        return true;
    }
    do {
        if (sp == 0) return false;
        e = stack[--sp];
    } while (e.t > t_max);
    return true;
}

/// The walk of one ray from `start` to its end (walk_step).
template <class NodeArch, class LeafArch, class Leaf>
inline void walk_single(const MeshView& m, const SingleRay<NodeArch, LeafArch>& r, Entry start, const float& t_max,
                        Leaf&& leaf) {
    Entry stack[kStack];
    int sp = 0;
    Entry e{start.child, start.count, 0.f};
    while (walk_step(m, r, t_max, leaf, e, sp, stack)) {
    }
}

}  // namespace mesh_detail

/// Closest hit of the ray (o, d) with the part of the mesh under `start` (the root: {0, 0,
/// 0}; a packet's stack entry when it hands a lane over) for t in (0, best): returns the new
/// best and fills hit when it shrank. Not inlined: the packet walks that hand lanes over keep
/// their own register allocation (measured: inlined, it cost their coherent rays 8 %).
template <class NodeArch, class LeafArch>
[[gnu::noinline]] inline float mesh_closest_single(const MeshView& m, const Vec3f& o, const Vec3f& d, float best,
                                                   MeshHit& hit,
                                                   mesh_detail::Entry start = {0, 0, 0.f}) {
    using namespace mesh_detail;
    if (!m.nodes || !(best > 0.f)) return best;
    const SingleRay<NodeArch, LeafArch> r(o, d);
    walk_single(m, r, start, best, [&](std::uint32_t first, std::uint32_t count) {
        single_leaf_closest(m, r, first, count, best, hit);
        return false;
    });
    return best;
}

/// mesh_closest_single for two rays at once, their walks interleaved step by step (walk_step).
/// A walk is a chain of dependent loads and compares (pop, node, child, leaf) that leaves most
/// of the core idle; a second, independent chain fills it. Each ray visits what it would
/// alone, in the same order, so it gets the same answer to the bit.
template <class NodeArch, class LeafArch>
[[gnu::noinline]] inline void mesh_closest_single_pair(const MeshView& m, const Vec3f* o, const Vec3f* d,
                                                       float* best, MeshHit* hit, mesh_detail::Entry start) {
    using namespace mesh_detail;
    const SingleRay<NodeArch, LeafArch> ra(o[0], d[0]), rb(o[1], d[1]);
    float best_a = best[0], best_b = best[1];
    MeshHit hit_a = hit[0], hit_b = hit[1];
    const auto leaf_a = [&](std::uint32_t first, std::uint32_t count) {
        single_leaf_closest(m, ra, first, count, best_a, hit_a);
        return false;
    };
    const auto leaf_b = [&](std::uint32_t first, std::uint32_t count) {
        single_leaf_closest(m, rb, first, count, best_b, hit_b);
        return false;
    };
    Entry stack_a[kStack], stack_b[kStack];
    Entry ea{start.child, start.count, 0.f}, eb = ea;
    int sp_a = 0, sp_b = 0;
    bool more_a = true, more_b = true;
    while (more_a && more_b) {
        more_a = walk_step(m, ra, best_a, leaf_a, ea, sp_a, stack_a);
        more_b = walk_step(m, rb, best_b, leaf_b, eb, sp_b, stack_b);
    }
    while (more_a) more_a = walk_step(m, ra, best_a, leaf_a, ea, sp_a, stack_a);
    while (more_b) more_b = walk_step(m, rb, best_b, leaf_b, eb, sp_b, stack_b);
    best[0] = best_a;
    best[1] = best_b;
    hit[0] = hit_a;
    hit[1] = hit_b;
}

/// Whether the mesh blocks the ray (o, d) for t in (0, t_max), under `start` as above.
template <class NodeArch, class LeafArch>
[[gnu::noinline]] inline bool mesh_any_single(const MeshView& m, const Vec3f& o, const Vec3f& d, float t_max,
                                              mesh_detail::Entry start = {0, 0, 0.f}) {
    using namespace mesh_detail;
    if (!m.nodes || !(t_max > 0.f)) return false;
    const SingleRay<NodeArch, LeafArch> r(o, d);
    bool blocked = false;
    walk_single(m, r, start, t_max, [&](std::uint32_t first, std::uint32_t count) {
        return blocked = single_leaf_any(m, r, first, count, t_max);
    });
    return blocked;
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
