#pragma once
// The SIMD mesh kernels: a packet of rays (already in the mesh's canonical space, as for the
// canonical shapes) walks the mesh's 8-wide BVH together; leaves run the watertight triangle
// test (shapes/triangle_math.h) on the whole packet, one broadcast triangle at a time.
// Hybrid: a stack entry that at most `single_lanes` lanes reached is finished by the
// single-ray walk (mesh_single_kernel.h), two lanes at a time. The caller chooses the
// threshold: the mesh's (MeshView::single_ray_lanes, for measurements), and for closest hits
// the larger of that and the stream's for scattered packets (scattered_packet_lanes).
// Included only by kernels/isa_*.cpp through intersect_kernel.h, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "kernels/lane_extremes.h"
#include "kernels/mesh_single_kernel.h"
#include "kernels/walk_stack.h"
#include "mesh/mesh_view.h"
#include "shapes/triangle_math.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

namespace mesh_detail {

struct PacketEntry {
    std::int32_t child;
    std::uint32_t count;
    float t;             ///< smallest entry distance of the lanes that hit the box
    std::uint32_t lanes;  ///< bit l: lane l hit the box
};

/// The packet's canonical rays, lane by lane, for the lanes handed to the single-ray walk.
template <class B>
struct PacketLanes {
    alignas(64) float ox[B::size], oy[B::size], oz[B::size], dx[B::size], dy[B::size], dz[B::size];
    PacketLanes(const Vec3T<B>& o, const Vec3T<B>& d) {
        o.x.store_aligned(ox);
        o.y.store_aligned(oy);
        o.z.store_aligned(oz);
        d.x.store_aligned(dx);
        d.y.store_aligned(dy);
        d.z.store_aligned(dz);
    }
    Vec3f origin(std::size_t l) const { return {ox[l], oy[l], oz[l]}; }
    Vec3f direction(std::size_t l) const { return {dx[l], dy[l], dz[l]}; }
};

/// Starts loading child j of node n, met by the lanes `bits` of a packet walk on a mesh larger
/// than the caches (MeshView::prefetched): the first 4 lines at its address (an inner node's
/// 256 bytes, or a leaf's first triangles, 36 bytes each, in leaf order), or for a child no lane
/// met, `cached` (lines in the cache already). A leaf's first line is its triangles' vertex
/// numbers (12 bytes each, leaf order; their positions follow from them, so cannot be fetched
/// ahead here). A select rather than a branch on the box test:
/// on a tree that does not fit the cache a mispredicted branch waits on the node's load.
inline void prefetch_met_child(const MeshView& m, const accel::WideNode& n, int j, std::uint32_t bits,
                               const void* cached) {
    const void* child = n.count[j] > 0 ? static_cast<const void*>(m.index + 3 * std::size_t(n.child[j]))
                                       : static_cast<const void*>(m.nodes + n.child[j]);
    simd::prefetch_lines(bits != 0 ? child : cached, sizeof(accel::WideNode));
}

/// Box test for the mesh walk. Boxes are padded outwards (accel::conservative_box) and the
/// far distance is widened by 2 gamma(3) (Ize 2013, "Robust BVH ray traversal"), so float
/// rounding in the slabs can never drop a box the ray touches: a ray through a shared edge
/// still reaches both triangles' leaves, flat boxes (axis-aligned triangles) included.
template <class B>
inline auto robust_box(const accel::WideNode& n, int j, const Vec3T<B>& o, const Vec3T<B>& inv, const B& t_max,
                       B& t_near) {
    B tn(0.f), tf = t_max;
    // min(x, y) / max(x, y) are the minps / maxps instructions, which give y when x is NaN:
    // the same bits as select(x < y, x, y) and select(x > y, x, y), in one instruction.
    const auto slab = [&](float lo, float hi, const B& oc, const B& ic) {
        const B a = (B(lo) - oc) * ic, b = (B(hi) - oc) * ic;
        const B mn = xsimd::min(a, b), mx = xsimd::max(b, a);
        tn = xsimd::max(mn, tn);  // NaN (0 * inf): the slab does not limit
        tf = xsimd::min(mx, tf);
    };
    slab(n.lo_x[j], n.hi_x[j], o.x, inv.x);
    slab(n.lo_y[j], n.hi_y[j], o.y, inv.y);
    slab(n.lo_z[j], n.hi_z[j], o.z, inv.z);
    t_near = tn;
    return tn <= tf * B(kWiden);
}

template <class B>
inline Vec3T<B> vertex(const MeshView& m, std::uint32_t k, int j) {
    const float* p = triangle_corner(m, k, j);
    return {B(p[0]), B(p[1]), B(p[2])};
}

/// The watertight test's axis permutation (kx, ky, kz as 0, 1, 2) when every lane of `live`
/// has the same one, as coherent packets (camera rays of a tile, shadow rays of a patch
/// towards one light) almost always do: the leaves then read each triangle's permuted
/// coordinates once, instead of choosing them lane by lane with 18 selects per triangle.
/// False when the lanes differ (or none is live).
template <class B>
inline bool shared_axes(const WatertightRay<B>& wr, std::uint32_t live, int axes[3]) {
    const auto axis = [live](const auto& is0, const auto& is1, int& out) {
        const std::uint32_t b0 = movemask_bits(is0) & live, b1 = movemask_bits(is1) & live;
        if ((b0 != 0 && b0 != live) || (b1 != 0 && b1 != live)) return false;
        out = b0 ? 0 : b1 ? 1 : 2;
        return true;
    };
    return live != 0 && axis(wr.kx0, wr.kx1, axes[0]) && axis(wr.ky0, wr.ky1, axes[1]) && axis(wr.kz0, wr.kz1, axes[2]);
}

/// The corners of triangle k relative to the rays' origins on the shared axes (shared_axes):
/// the same operations, per lane, as triangle_sheared's subtraction then pick, so the same bits.
template <class B>
struct SharedAxesTriangles {
    int axis[3];
    Vec3T<B> o_perm;  ///< the origins' coordinates on those axes
    SharedAxesTriangles(const int axes[3], const Vec3T<B>& o) {
        const B oc[3] = {o.x, o.y, o.z};
        for (int a = 0; a < 3; ++a) axis[a] = axes[a];
        o_perm = {oc[axes[0]], oc[axes[1]], oc[axes[2]]};
    }
    Vec3T<B> corner(const MeshView& m, std::uint32_t k, int j) const {
        const float* p = triangle_corner(m, k, j);
        return {B(p[axis[0]]) - o_perm.x, B(p[axis[1]]) - o_perm.y, B(p[axis[2]]) - o_perm.z};
    }
    tri_detail::Sheared<B> sheared(const WatertightRay<B>& wr, const MeshView& m, std::uint32_t k) const {
        return tri_detail::shear(wr, corner(m, k, 0), corner(m, k, 1), corner(m, k, 2));
    }
};

/// The corners of triangle k relative to the rays' origins on each lane's own axes, chosen by
/// the lane-permute instruction (vpermps) from one load of the corner's 3 floats, where
/// triangle_sheared picks them with two selects per coordinate: 3 loads and 9 permutes per
/// triangle instead of 9 broadcasts and 18 selects. The same values, so the same bits.
/// AVX2 and AVX-512 only; the SSE levels keep the selects.
template <class B>
struct LanePermutedTriangles {
    LanePermutedTriangles(const WatertightRay<B>&, const Vec3T<B>&) {}
    tri_detail::Sheared<B> sheared(const WatertightRay<B>& wr, const MeshView& m, std::uint32_t k) const {
        return triangle_sheared(wr, vertex<B>(m, k, 0), vertex<B>(m, k, 1), vertex<B>(m, k, 2));
    }
};
#if defined(__AVX2__)
template <class B>
    requires(B::size == 8 || B::size == 16)
struct LanePermutedTriangles<B> {
    using I = xsimd::batch<std::int32_t, typename B::arch_type>;
    I index[3];       ///< kx, ky, kz of each lane as 0, 1, 2
    Vec3T<B> o_perm;  ///< each lane's origin on its axes
    LanePermutedTriangles(const WatertightRay<B>& wr, const Vec3T<B>& o) {
        const auto axis = [](const auto& is0, const auto& is1) {
            return xsimd::select(xsimd::bool_cast(is0), I(0), xsimd::select(xsimd::bool_cast(is1), I(1), I(2)));
        };
        index[0] = axis(wr.kx0, wr.kx1);
        index[1] = axis(wr.ky0, wr.ky1);
        index[2] = axis(wr.kz0, wr.kz1);
        o_perm = {tri_detail::pick(wr.kx0, wr.kx1, o), tri_detail::pick(wr.ky0, wr.ky1, o),
                  tri_detail::pick(wr.kz0, wr.kz1, o)};
    }
    /// Lane l of the result: p[idx[l]], from a load of p[0 .. 3) alone (masked: the corner may
    /// be the last 3 floats of the array).
    static B permute(const I& idx, const float* p) {
#if defined(__AVX512F__)
        if constexpr (B::size == 16) return B(_mm512_permutexvar_ps(idx, _mm512_maskz_loadu_ps(0x7, p)));
#endif
        if constexpr (B::size == 8)
            return B(_mm256_permutevar8x32_ps(_mm256_maskload_ps(p, _mm256_setr_epi32(-1, -1, -1, 0, 0, 0, 0, 0)),
                                              idx));
    }
    Vec3T<B> corner(const MeshView& m, std::uint32_t k, int j) const {
        const float* p = triangle_corner(m, k, j);
        return {permute(index[0], p) - o_perm.x, permute(index[1], p) - o_perm.y, permute(index[2], p) - o_perm.z};
    }
    tri_detail::Sheared<B> sheared(const WatertightRay<B>& wr, const MeshView& m, std::uint32_t k) const {
        return tri_detail::shear(wr, corner(m, k, 0), corner(m, k, 1), corner(m, k, 2));
    }
};
#endif

/// The lanes of `lanes` whose ray meets one of node n's child boxes within (0, t_max). A
/// packet handed to the single-ray walk at the root first passes this one packet test, so
/// that a lane missing the whole mesh (a ray inside one glass mesh, against the scene's other
/// meshes) costs no single-ray set-up and root visit of its own.
template <class B>
inline std::uint32_t lanes_meeting_children(const accel::WideNode& n, const Vec3T<B>& o, const Vec3T<B>& inv,
                                            const B& t_max, std::uint32_t lanes) {
    auto any_child = t_max != t_max;  // all false (t_max is never NaN)
    for (int j = 0; j < accel::kNodeWidth && n.child[j] >= 0; ++j) {
        B tn;
        any_child = any_child || robust_box(n, j, o, inv, t_max, tn);
    }
    return lanes & movemask_bits(any_child);
}

}  // namespace mesh_detail

/// A packet whose live rays' directions all lie within about 73 degrees of their mean keeps
/// the packet walk: measured (docs/performance.md, "A switch per ray generation"), the hybrid
/// pays only on packets scattered wider than that (rays refracted by a scanned mesh's facets)
/// and costs on the narrower ones (rays through a smooth lens).
inline constexpr float kScatteredPacketCos = 0.3f;

/// Meshes of fewer triangles keep the packet walk whatever their packets' directions: their
/// trees are too shallow for the single rays' own walks to pay. Measured on diffuse bounces
/// (docs/global-illumination.md, degree 6, intersect CPU time at -j1): Embree's Cornell box
/// (5 meshes of 2 - 12 triangles) 0.112 s as packets against 0.139 s with the hand-over from
/// generation 4 and 0.174 s from generation 1; the 3 674-triangle bunny in a box 0.33 s as
/// packets against 0.24 s with the hand-over.
inline constexpr std::uint32_t kHybridMinTriangles = 256;

/// The hybrid threshold `lanes` (RayView::single_ray_lanes) for mesh m: 0 below
/// kHybridMinTriangles triangles.
inline std::uint32_t hybrid_lanes_for(const MeshView& m, std::uint32_t lanes) {
    return m.n_tris < kHybridMinTriangles ? 0u : lanes;
}

/// The stream's hybrid threshold (RayView::single_ray_lanes) for the canonical packet with
/// directions d and live lanes `live`: `lanes` when the packet is scattered (some live
/// direction is more than acos(kScatteredPacketCos) from their mean), 0 otherwise.
template <class B, class M>
inline std::uint32_t scattered_packet_lanes(const Vec3T<B>& d, const M& live, std::uint32_t lanes) {
    if (lanes == 0) return 0;
    const B inv_len = B(1.f) / xsimd::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    const B nx = xsimd::select(live, d.x * inv_len, B(0.f)), ny = xsimd::select(live, d.y * inv_len, B(0.f)),
            nz = xsimd::select(live, d.z * inv_len, B(0.f));
    const float mx = xsimd::hadd(nx), my = xsimd::hadd(ny), mz = xsimd::hadd(nz);  // xsimd 8: hadd sums the lanes
    const float m = std::sqrt(mx * mx + my * my + mz * mz);
    if (!(m > 0.f)) return lanes;  // no live lane, or directions that cancel out
    const B cos_to_mean = (nx * B(mx) + ny * B(my) + nz * B(mz)) * B(1.f / m);
    return xsimd::any(live && (cos_to_mean < B(kScatteredPacketCos))) ? lanes : 0u;
}

/// mesh_closest_packet's walk; the leaves read each triangle's permuted corners through
/// `corners` (SharedAxesTriangles or LanePermutedTriangles).
template <class B, class Corners>
inline void mesh_closest_packet_walk(const MeshView& m, const Vec3T<B>& o, const Vec3T<B>& d, B& best,
                                     std::int32_t* prim, float* u, float* v, std::uint32_t single_lanes,
                                     const WatertightRay<B>& wr, const Corners& corners) {
    using namespace mesh_detail;
    using I = xsimd::batch<std::int32_t, typename B::arch_type>;
    using Archs = SingleRayArchs<typename B::arch_type>;
    constexpr std::size_t W = B::size;
    const B start = best;
    float best_max = lanes_max(best);
    const Vec3T<B> inv{B(1.f) / d.x, B(1.f) / d.y, B(1.f) / d.z};
    B bu(0.f), bv(0.f);
    I bprim(-1);
    // Lanes handed to the single-ray walk: rays, then the hits as arrays, loaded back after.
    const PacketLanes<B> lanes(o, d);
    const auto hand_over = [&](const PacketEntry& e) {
        alignas(64) float t_l[W], u_l[W], v_l[W];
        alignas(64) std::int32_t p_l[W];
        best.store_aligned(t_l);
        bu.store_aligned(u_l);
        bv.store_aligned(v_l);
        bprim.store_aligned(p_l);
        // The lanes to finish, walked in pairs (mesh_closest_single_pair), the odd one alone.
        // Measured (docs/performance.md, "The closest walk on large meshes"): pairs made the
        // single-ray walk 1.15 - 1.44x faster on closest hits; groups of 4 gained nothing.
        int go[W], n = 0;
        Vec3f og[W], dg[W];
        float tg[W];
        MeshHit hg[W];
        for (std::size_t l = 0; l < W; ++l)
            if ((e.lanes >> l & 1u) && !(e.t > t_l[l])) {
                og[n] = lanes.origin(l);
                dg[n] = lanes.direction(l);
                hg[n] = {p_l[l], u_l[l], v_l[l]};
                tg[n] = t_l[l];
                go[n++] = int(l);
            }
        const mesh_detail::Entry from{e.child, e.count, 0.f};
        int k = 0;
        for (; k + 2 <= n; k += 2)
            mesh_closest_single_pair<typename Archs::node, typename Archs::leaf>(m, og + k, dg + k, tg + k, hg + k, from);
        if (k < n)
            tg[k] = mesh_closest_single<typename Archs::node, typename Archs::leaf>(m, og[k], dg[k], tg[k], hg[k], from);
        for (int q = 0; q < n; ++q) {
            const int l = go[q];
            t_l[l] = tg[q];
            p_l[l] = hg[q].prim;
            u_l[l] = hg[q].u;
            v_l[l] = hg[q].v;
        }
        best = B::load_aligned(t_l);
        bu = B::load_aligned(u_l);
        bv = B::load_aligned(v_l);
        bprim = I::load_aligned(p_l);
    };
    PacketEntry stack[kStack];
    int sp = 0;
    std::uint32_t live = movemask_bits(best > B(0.f));
    if (std::uint32_t(std::popcount(live)) <= single_lanes) {
        live = lanes_meeting_children(m.nodes[0], o, inv, best, live);
        if (live == 0) return;
    }
    stack[sp++] = {0, 0, 0.f, live};
    while (sp > 0) {
        const PacketEntry e = stack[--sp];
        if (e.t > best_max) continue;
        if (std::uint32_t(std::popcount(e.lanes)) <= single_lanes) {
            hand_over(e);
            best_max = lanes_max(best);
            continue;
        }
        if (e.count > 0) {
            for (std::uint32_t k = std::uint32_t(e.child); k < std::uint32_t(e.child) + e.count; ++k) {
                const auto sheared = corners.sheared(wr, m, k);
                if (!xsimd::any(triangle_may_hit(sheared, best))) continue;
                // A tie (two triangles at one t: a ray through their shared edge or vertex)
                // goes to the lower triangle number, as in the single-ray walk: the answer
                // must not depend on the order the leaves are met in, which depends on the
                // packet's other rays (adaptive sampling traces a pixel's corner in different
                // packets for a whole image and for a tile rendered alone).
                const TriangleHit<B> h = triangle_hit_sheared<true>(sheared, B(0.f), best);
                const auto closer =
                    h.t < best || (h.t == best && xsimd::bool_cast(I(std::int32_t(k)) < bprim));
                if (!xsimd::any(closer)) continue;
                best = xsimd::select(closer, h.t, best);
                bu = xsimd::select(closer, h.u, bu);
                bv = xsimd::select(closer, h.v, bv);
                bprim = xsimd::select(xsimd::bool_cast(closer), I(std::int32_t(k)), bprim);
            }
            best_max = lanes_max(best);
            continue;
        }
        const accel::WideNode& n = m.nodes[e.child];
        PacketEntry hits[accel::kNodeWidth];
        int nh = 0;
        // The met children, farthest first (so the nearest is popped first), equal distances in
        // the children's order. On a mesh larger than the caches every child's entry is written
        // and the count moves on where a lane met it, then the entries are sorted once: the
        // same order as inserting each as met, which smaller meshes keep (their branches
        // predict well; written as one loop body for both, the small form lost 3 - 9 %:
        // docs/performance.md, "The closest walk on large meshes").
        if (m.prefetched) {
            for (int j = 0; j < accel::kNodeWidth && n.child[j] >= 0; ++j) {
                B tn;
                const auto hit = robust_box(n, j, o, inv, best, tn);
                const std::uint32_t bits = movemask_bits(hit);
                prefetch_met_child(m, n, j, bits, hits);
                hits[nh] = {n.child[j], n.count[j], lanes_min_where(tn, hit), single_lanes > 0 ? bits : ~0u};
                nh += int(bits != 0);
            }
            push_sorted(stack, sp, hits, nh);
            continue;
        }
        for (int j = 0; j < accel::kNodeWidth && n.child[j] >= 0; ++j) {
            B tn;
            const auto hit = robust_box(n, j, o, inv, best, tn);
            if (!xsimd::any(hit)) continue;
            const PacketEntry en{n.child[j], n.count[j], lanes_min_where(tn, hit),
                                 single_lanes > 0 ? movemask_bits(hit) : ~0u};
            int k = nh++;
            while (k > 0 && hits[k - 1].t < en.t) {
                hits[k] = hits[k - 1];
                --k;
            }
            hits[k] = en;
        }
        for (int k = 0; k < nh; ++k) stack[sp++] = hits[k];
    }
    const auto improved = best < start;
    if (!prim || !xsimd::any(improved)) return;
    alignas(64) std::int32_t p_out[W];
    alignas(64) float u_out[W], v_out[W];
    alignas(64) bool go[W];
    bprim.store_aligned(p_out);
    bu.store_aligned(u_out);
    bv.store_aligned(v_out);
    improved.store_aligned(go);
    for (std::size_t l = 0; l < W; ++l)
        if (go[l]) {
            prim[l] = p_out[l];
            u[l] = u_out[l];
            v[l] = v_out[l];
        }
}

/// Closest hit of the canonical packet (o, d) with the mesh for t in (0, best): shrinks best
/// per lane and, for the lanes it shrank, writes triangle number and barycentrics into
/// prim/u/v[0 .. W) (when prim is not null). single_lanes: see the hybrid above (0: packet only).
/// The walk is built twice, for packets whose live lanes share the triangle test's axes and
/// for the others (shared_axes).
template <class B>
inline void mesh_closest_packet(const MeshView& m, const Vec3T<B>& o, const Vec3T<B>& d, B& best, std::int32_t* prim,
                                float* u, float* v, std::uint32_t single_lanes) {
    if (!m.nodes || !(lanes_max(best) > 0.f)) return;
    const WatertightRay<B> wr = watertight_ray(o, d);
    using namespace mesh_detail;
    int axes[3];
    if (shared_axes(wr, movemask_bits(best > B(0.f)), axes))
        mesh_closest_packet_walk(m, o, d, best, prim, u, v, single_lanes, wr, SharedAxesTriangles<B>(axes, o));
    else
        mesh_closest_packet_walk(m, o, d, best, prim, u, v, single_lanes, wr, LanePermutedTriangles<B>(wr, o));
}

/// mesh_any_packet's walk; `corners` as for mesh_closest_packet_walk.
template <class B, class M, class Corners>
inline M mesh_any_packet_walk(const MeshView& m, const Vec3T<B>& o, const Vec3T<B>& d, const B& t_max, M open,
                              std::uint32_t single_lanes, const WatertightRay<B>& wr, const Corners& corners) {
    using namespace mesh_detail;
    using Archs = SingleRayArchs<typename B::arch_type>;
    constexpr std::size_t W = B::size;
    M blocked = B(0.f) != B(0.f);
    const Vec3T<B> inv{B(1.f) / d.x, B(1.f) / d.y, B(1.f) / d.z};
    const PacketLanes<B> lanes(o, d);
    // The open lanes of e, finished one by one by the single-ray walk.
    const auto hand_over = [&](const PacketEntry& e) {
        alignas(64) float t_l[W], blocked_l[W];
        t_max.store_aligned(t_l);
        xsimd::select(blocked, B(1.f), B(0.f)).store_aligned(blocked_l);
        const std::uint32_t go = e.lanes & movemask_bits(open);
        for (std::size_t l = 0; l < W; ++l)
            if ((go >> l & 1u) && mesh_any_single<typename Archs::node, typename Archs::leaf>(
                                      m, lanes.origin(l), lanes.direction(l), t_l[l], {e.child, e.count, 0.f}))
                blocked_l[l] = 1.f;
        blocked = B::load_aligned(blocked_l) != B(0.f);
        open = open && !blocked;
    };
    PacketEntry stack[kStack];
    int sp = 0;
    stack[sp++] = {0, 0, 0.f, movemask_bits(open)};
    while (sp > 0) {
        const PacketEntry e = stack[--sp];
        if ((e.lanes & movemask_bits(open)) == 0) continue;  // the lanes that met it have been blocked since
        if (single_lanes > 0 && std::uint32_t(std::popcount(e.lanes & movemask_bits(open))) <= single_lanes) {
            hand_over(e);
            if (!xsimd::any(open)) break;
            continue;
        }
        if (e.count > 0) {
            for (std::uint32_t k = std::uint32_t(e.child); k < std::uint32_t(e.child) + e.count; ++k) {
                const auto now = open && triangle_blocks_sheared(corners.sheared(wr, m, k), t_max);
                blocked = blocked || now;
                open = open && !now;
            }
            if (!xsimd::any(open)) break;  // every lane is blocked
            continue;
        }
        // Every child's entry is written and the stack grows by one where a lane met it: no
        // branch on the box test. Measured (docs/performance.md, "Shadow packets push without
        // a branch"): 1.17x on the 1.3M mesh's shadow rays, renderer occlusion 0.92 - 0.94x;
        // the bunny's shadow rays in the harness, whose branches predict well, 0.96x.
        const accel::WideNode& n = m.nodes[e.child];
        for (int j = 0; j < accel::kNodeWidth && n.child[j] >= 0; ++j) {
            B tn;
            const std::uint32_t bits = movemask_bits(robust_box(n, j, o, inv, t_max, tn) && open);
            // docs/performance.md, "The closest walk on large meshes"
            if (m.prefetched) prefetch_met_child(m, n, j, bits, stack);
            stack[sp] = {n.child[j], n.count[j], 0.f, bits};
            sp += int(bits != 0);
        }
    }
    return blocked;
}

/// Any hit for t in (0, t_max) of the lanes in `open`: the lanes the mesh blocks.
/// single_lanes: see the hybrid above (0: packet only). Built twice, as mesh_closest_packet.
template <class B, class M>
inline M mesh_any_packet(const MeshView& m, const Vec3T<B>& o, const Vec3T<B>& d, const B& t_max, M open,
                         std::uint32_t single_lanes) {
    if (!m.nodes || !xsimd::any(open)) return B(0.f) != B(0.f);
    const WatertightRay<B> wr = watertight_ray(o, d);
    using namespace mesh_detail;
    int axes[3];
    if (shared_axes(wr, movemask_bits(open), axes))
        return mesh_any_packet_walk(m, o, d, t_max, open, single_lanes, wr, SharedAxesTriangles<B>(axes, o));
    return mesh_any_packet_walk(m, o, d, t_max, open, single_lanes, wr, LanePermutedTriangles<B>(wr, o));
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE

#include "kernels/mesh_stream_kernel.h"
