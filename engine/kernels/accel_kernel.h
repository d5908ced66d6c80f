#pragma once
// The hierarchy traversal kernels, templated on the xsimd arch. Included only by the
// kernels/isa_<level>_accel.cpp files, each inside its own namespace (see intersect_kernel.h).
//
// Two ways to walk the 8-wide tree (accel/bvh.h):
// - packet: SIMD-width rays walk it together; each child box is tested against all lanes at
//   once and visited if any active lane hits it; leaves run the shape math on the packet.
// - single: one ray walks it; the 8 child boxes of a node are tested in one SIMD operation
//   (NodeArch: 8 lanes, or 4 lanes twice on SSE); leaves run the shape math on the ray
//   broadcast into a batch (so no scalar shape code is instantiated with this level's flags).
// Which wins for which ray kind is measured in docs/performance.md ("## BVH").
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <bit>
#include <limits>

#include "kernels/accel_kernel_table.h"
#include "kernels/intersect_kernel.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

namespace accel_detail {

constexpr int kStack = accel::kNodeWidth * 64;
constexpr float kInfF = std::numeric_limits<float>::infinity();

struct StackEntry {
    std::int32_t child;
    std::uint32_t count;
    float t;  ///< smallest entry distance of any lane into the box
    /// Packet walks: bit l set when lane l hit the box. A mesh in a leaf is walked by these
    /// lanes only, so that a packet spread over several small instances does not walk each of
    /// them with all its rays.
    std::uint32_t lanes = ~0u;
};

/// Slab test of a packet (or a broadcast ray) against boxes given per lane. NaN slab
/// distances are ignored (a grazing ray counts as hitting). Returns the entry distance (>= 0)
/// and whether [t_near, t_far] with t_far <= t_max is non-empty.
template <class B>
inline auto slab_test(const B& lox, const B& loy, const B& loz, const B& hix, const B& hiy, const B& hiz,
                      const Vec3T<B>& o, const Vec3T<B>& inv, const B& t_max, B& t_near) {
    using T = typename B::value_type;
    B tn(T(0)), tf = t_max;
    // min(x, y) / max(x, y) are the minps / maxps instructions, which give y when x is NaN:
    // the same bits as select(x < y, x, y) and select(x > y, x, y), in one instruction.
    const auto slab = [&](const B& lo, const B& hi, const B& oc, const B& ic) {
        const B a = (lo - oc) * ic, b = (hi - oc) * ic;
        const B mn = xsimd::min(a, b), mx = xsimd::max(b, a);
        tn = xsimd::max(mn, tn);  // NaN (0 * inf): the slab does not limit
        tf = xsimd::min(mx, tf);
    };
    slab(lox, hix, o.x, inv.x);
    slab(loy, hiy, o.y, inv.y);
    slab(loz, hiz, o.z, inv.z);
    t_near = tn;
    return tn <= tf;
}

/// Starts loading the object records of a leaf that a walk has just met: with many objects
/// the records (64 bytes each) miss the caches, and the walk would wait on them when it pops
/// the leaf; the leaves nearer than it are tested meanwhile.
inline void prefetch_leaf(const AccelView& bvh, std::int32_t first, std::uint32_t count) {
    simd::prefetch_lines(bvh.prims + first, sizeof(KernelObject) * count);
}

/// Runs f(ShapeMath{}) for a stored kind (shapes/shapes.h's generated switch). Meshes are
/// not closed-form: the leaf loops call the mesh walk instead, before this.
template <class F>
inline void with_shape(std::uint32_t kind, F&& f) {
    visit_shape(ShapeKind(kind), f);
}

/// A mesh in a leaf of the scene's tree that at most this many of a packet's W live lanes
/// reach is walked by those lanes one at a time (two at a time, the paired single-ray walk):
/// the mesh is small against the packet (instances far away, or a packet on a silhouette),
/// and the lanes' paths through its tree share little. Measured (docs/performance.md,
/// "Instances"): on 10,000 instances 1.3 - 1.5x less intersect time at 3/4 of the packet, the
/// 100-instance scene level; occlusion gained nothing, so shadow packets keep the packet walk.
template <std::size_t W>
inline constexpr std::uint32_t kInstanceSingleRayLanes = std::uint32_t(W * 3 / 4);

/// A mesh object in a leaf: the packet at `base` into the mesh's canonical space, then its
/// own hierarchy, walked by the lanes in `lanes` (those that reached the leaf). Shrinks best
/// (and writes the mesh hit of the lanes it shrank).
template <class Arch>
inline void mesh_leaf_closest(const RayView& rays, std::size_t base, const ObjectXf& ob,
                              xsimd::batch<float, Arch>& best, std::uint32_t lanes) {
    using B = xsimd::batch<float, Arch>;
    const auto in_box = mask_from_bits<Arch>(lanes);
    B walked = xsimd::select(in_box, best, B(0.f));  // the other lanes sit the walk out
    const auto live = walked > B(0.f);
    const RayPacket<B> r{{B::load_aligned(rays.ox + base), B::load_aligned(rays.oy + base), B::load_aligned(rays.oz + base)},
                         {B::load_aligned(rays.dx + base), B::load_aligned(rays.dy + base), B::load_aligned(rays.dz + base)}};
    const RayPacket<B> c = to_canonical<B, float>(r, ob);
    mesh_closest_packet(*ob.mesh, c.o, c.d, walked, rays.prim ? rays.prim + base : nullptr,
                        rays.bu ? rays.bu + base : nullptr, rays.bv ? rays.bv + base : nullptr,
                        std::uint32_t(std::popcount(movemask_bits(live))) <= kInstanceSingleRayLanes<B::size>
                            ? std::uint32_t(B::size)
                            : std::max(ob.mesh->single_ray_lanes,
                                       scattered_packet_lanes(c.d, live, hybrid_lanes_for(*ob.mesh, rays.single_ray_lanes))));
    best = xsimd::select(in_box, walked, best);
}

/// One ray in a mesh object's canonical space (computed on a broadcast batch, so exactly as
/// the packet kernels transform the same ray).
template <class Arch>
inline void single_to_canonical(const Vec3f& o, const Vec3f& d, const ObjectXf& ob, Vec3f& oc, Vec3f& dc) {
    using B = xsimd::batch<float, Arch>;
    const RayPacket<B> r{{B(o.x), B(o.y), B(o.z)}, {B(d.x), B(d.y), B(d.z)}};
    const RayPacket<B> c = to_canonical<B, float>(r, ob);
    oc = {c.o.x.get(0), c.o.y.get(0), c.o.z.get(0)};
    dc = {c.d.x.get(0), c.d.y.get(0), c.d.z.get(0)};
}

/// A mesh object against one ray (single-ray traversal): the single-ray mesh walk
/// (kernels/mesh_single_kernel.h); the hit is written at index i of the mesh-hit arrays.
template <class Arch>
inline float mesh_single_closest(const RayView& rays, std::size_t i, const Vec3f& o, const Vec3f& d, const ObjectXf& ob,
                                 float t_max) {
    using Archs = SingleRayArchs<Arch>;
    Vec3f oc, dc;
    single_to_canonical<Arch>(o, d, ob, oc, dc);
    MeshHit h;
    const float t = mesh_closest_single<typename Archs::node, typename Archs::leaf>(*ob.mesh, oc, dc, t_max, h);
    if (t < t_max && rays.prim) {
        rays.prim[i] = h.prim;
        rays.bu[i] = h.u;
        rays.bv[i] = h.v;
    }
    return t < t_max ? t : kInfF;
}

template <class Arch>
inline bool mesh_single_any(const Vec3f& o, const Vec3f& d, const ObjectXf& ob, float t_max) {
    using Archs = SingleRayArchs<Arch>;
    Vec3f oc, dc;
    single_to_canonical<Arch>(o, d, ob, oc, dc);
    return mesh_any_single<typename Archs::node, typename Archs::leaf>(*ob.mesh, oc, dc, t_max);
}

/// Nearest hit t in (0, t_max) of the rays at `base` (W lanes, in memory) with one object, in
/// the shape's precision; float result. Shapes solved in double run in two or more halves.
template <class Arch, class Shape>
inline xsimd::batch<float, Arch> object_t(const RayView& rays, std::size_t base, const ObjectXf& ob,
                                          const xsimd::batch<float, Arch>& t_max) {
    using BF = xsimd::batch<float, Arch>;
    using T = typename ComputeType<Shape>::type;
    if constexpr (std::is_same_v<T, float>) {
        const RayPacket<BF> r{{BF::load_aligned(rays.ox + base), BF::load_aligned(rays.oy + base),
                               BF::load_aligned(rays.oz + base)},
                              {BF::load_aligned(rays.dx + base), BF::load_aligned(rays.dy + base),
                               BF::load_aligned(rays.dz + base)}};
        const RayPacket<BF> c = to_canonical<BF, float>(r, ob);
        if constexpr (requires { Shape::may_hit(c.o, c.d); })
            if (!xsimd::any(Shape::may_hit(c.o, c.d))) return BF(kInfF);  // every lane misses: skip the solve
        return Shape::template hit_t<BF>(c.o, c.d, BF(ob.param), BF(0.f), t_max);
    } else {
        using BD = xsimd::batch<double, Arch>;
        alignas(64) float tm[BF::size], out[BF::size];
        t_max.store_aligned(tm);
        for (std::size_t h = 0; h < BF::size; h += BD::size) {
            const RayPacket<BD> r{{load_lanes<BD>(rays.ox + base + h), load_lanes<BD>(rays.oy + base + h),
                                   load_lanes<BD>(rays.oz + base + h)},
                                  {load_lanes<BD>(rays.dx + base + h), load_lanes<BD>(rays.dy + base + h),
                                   load_lanes<BD>(rays.dz + base + h)}};
            const RayPacket<BD> c = to_canonical<BD, double>(r, ob);
            const BD t = Shape::template hit_t<BD>(c.o, c.d, BD(double(ob.param)), BD(0.0), load_lanes<BD>(tm + h));
            alignas(64) double td[BD::size];
            t.store_aligned(td);
            for (std::size_t l = 0; l < BD::size; ++l) out[h + l] = float(td[l]);
        }
        return BF::load_aligned(out);
    }
}

/// The same for one ray broadcast into every lane (single-ray traversal); returns lane 0.
template <class Arch, class Shape>
inline float object_t_single(const Vec3f& o, const Vec3f& d, const ObjectXf& ob, float t_max) {
    using T = typename ComputeType<Shape>::type;
    using B = xsimd::batch<T, Arch>;
    const RayPacket<B> r{{B(T(o.x)), B(T(o.y)), B(T(o.z))}, {B(T(d.x)), B(T(d.y)), B(T(d.z))}};
    const RayPacket<B> c = to_canonical<B, T>(r, ob);
    if constexpr (requires { Shape::may_hit(c.o, c.d); })
        if (!xsimd::any(Shape::may_hit(c.o, c.d))) return kInfF;  // the line surely misses: skip the solve
    const B t = Shape::template hit_t<B>(c.o, c.d, B(T(ob.param)), B(T(0)), B(T(t_max)));
    return float(t.get(0));
}

}  // namespace accel_detail

template <class Arch>
void bvh_closest_packet(const AccelView& bvh, RayView rays, std::int32_t* object) {
    const simd::FlushDenormals ftz;  // see simd/lanes.h
    using namespace accel_detail;
    using B = xsimd::batch<float, Arch>;
    constexpr std::size_t W = B::size;
    StackEntry stack[kStack];
    for (std::size_t i = 0; i < rays.count; i += W) {
        const Vec3T<B> o{B::load_aligned(rays.ox + i), B::load_aligned(rays.oy + i), B::load_aligned(rays.oz + i)};
        const Vec3T<B> d{B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i), B::load_aligned(rays.dz + i)};
        const Vec3T<B> inv{B(1.f) / d.x, B(1.f) / d.y, B(1.f) / d.z};
        B best = B::load_aligned(rays.t_max + i);
        const B start = best;
        B best_id(-1.f);
        float best_max = lanes_max(best);
        if (!(best_max > 0.f)) continue;
        int sp = 0;
        stack[sp++] = {0, 0, 0.f};
        while (sp > 0) {
            const StackEntry e = stack[--sp];
            if (e.t > best_max) continue;
            if (e.count > 0) {
                for (std::uint32_t k = e.child; k < e.child + e.count; ++k) {
                    const KernelObject& ob = bvh.prims[k];
                    if (ob.xf.kind == std::uint32_t(ShapeKind::Mesh)) {
                        const B before = best;
                        mesh_leaf_closest<Arch>(rays, i, ob.xf, best, e.lanes);
                        best_id = xsimd::select(best < before, B(float(ob.xf.id)), best_id);
                        continue;
                    }
                    with_shape(ob.xf.kind, [&](auto shape) {
                        const B t = object_t<Arch, decltype(shape)>(rays, i, ob.xf, best);
                        const auto closer = t < best;
                        best = xsimd::select(closer, t, best);
                        best_id = xsimd::select(closer, B(float(ob.xf.id)), best_id);
                    });
                }
                best_max = lanes_max(best);
                continue;
            }
            const accel::WideNode& n = bvh.nodes[e.child];
            StackEntry hits[accel::kNodeWidth];
            int nh = 0;
            for (int j = 0; j < accel::kNodeWidth && n.child[j] >= 0; ++j) {
                B tn;
                const auto hit = slab_test(B(n.lo_x[j]), B(n.lo_y[j]), B(n.lo_z[j]), B(n.hi_x[j]), B(n.hi_y[j]),
                                           B(n.hi_z[j]), o, inv, best, tn);
                if (!xsimd::any(hit)) continue;
                if (n.count[j] > 0) prefetch_leaf(bvh, n.child[j], n.count[j]);
                const float t_min = lanes_min_where(tn, hit);
                hits[nh++] = {n.child[j], n.count[j], t_min, movemask_bits(hit)};
            }
            push_sorted(stack, sp, hits, nh);
        }
        if (xsimd::any(best < start)) store_closest(rays, object, i, best, best_id);
    }
}

template <class Arch>
void bvh_any_packet(const AccelView& bvh, RayView rays) {
    const simd::FlushDenormals ftz;  // see simd/lanes.h
    using namespace accel_detail;
    using B = xsimd::batch<float, Arch>;
    constexpr std::size_t W = B::size;
    StackEntry stack[kStack];
    for (std::size_t i = 0; i < rays.count; i += W) {
        B t_max = B::load_aligned(rays.t_max + i);
        auto open = t_max > B(0.f);
        if (!xsimd::any(open)) continue;
        const Vec3T<B> o{B::load_aligned(rays.ox + i), B::load_aligned(rays.oy + i), B::load_aligned(rays.oz + i)};
        const Vec3T<B> d{B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i), B::load_aligned(rays.dz + i)};
        const Vec3T<B> inv{B(1.f) / d.x, B(1.f) / d.y, B(1.f) / d.z};
        int sp = 0;
        stack[sp++] = {0, 0, 0.f};
        while (sp > 0) {
            const StackEntry e = stack[--sp];
            if (e.count > 0) {
                for (std::uint32_t k = e.child; k < e.child + e.count && xsimd::any(open); ++k) {
                    const KernelObject& ob = bvh.prims[k];
                    if (ob.xf.kind == std::uint32_t(ShapeKind::Mesh)) {
                        const RayPacket<B> r{{B::load_aligned(rays.ox + i), B::load_aligned(rays.oy + i),
                                              B::load_aligned(rays.oz + i)},
                                             {B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i),
                                              B::load_aligned(rays.dz + i)}};
                        const RayPacket<B> c = to_canonical<B, float>(r, ob.xf);
                        open = open && !mesh_any_packet(*ob.xf.mesh, c.o, c.d, t_max,
                                                        open && mask_from_bits<Arch>(e.lanes),
                                                        ob.xf.mesh->single_ray_lanes);
                        t_max = xsimd::select(open, t_max, B(0.f));
                        continue;
                    }
                    with_shape(ob.xf.kind, [&](auto shape) {
                        const B t = object_t<Arch, decltype(shape)>(rays, i, ob.xf, t_max);
                        open = open && !(t < t_max);
                        t_max = xsimd::select(open, t_max, B(0.f));
                    });
                }
                if (!xsimd::any(open)) break;  // early exit: the whole packet is blocked
                continue;
            }
            const accel::WideNode& n = bvh.nodes[e.child];
            for (int j = 0; j < accel::kNodeWidth && n.child[j] >= 0; ++j) {
                B tn;
                const auto hit = slab_test(B(n.lo_x[j]), B(n.lo_y[j]), B(n.lo_z[j]), B(n.hi_x[j]), B(n.hi_y[j]),
                                           B(n.hi_z[j]), o, inv, t_max, tn) && open;
                if (!xsimd::any(hit)) continue;
                if (n.count[j] > 0) prefetch_leaf(bvh, n.child[j], n.count[j]);
                stack[sp++] = {n.child[j], n.count[j], 0.f, movemask_bits(hit)};
            }
        }
        alignas(64) float out[W];
        t_max.store_aligned(out);
        for (std::size_t l = 0; l < W && i + l < rays.count; ++l)
            if (out[l] <= 0.f) rays.t_max[i + l] = 0.f;
    }
}

/// One ray against the 8 children of a node: hit children (entry distance) into hits[].
template <class NodeArch>
inline int node_hits_single(const AccelView& bvh, const accel::WideNode& n, const Vec3f& o, const Vec3f& inv,
                            float t_max, accel_detail::StackEntry* hits) {
    using namespace accel_detail;
    using NB = xsimd::batch<float, NodeArch>;
    constexpr std::size_t NW = NB::size;
    const Vec3T<NB> ob{NB(o.x), NB(o.y), NB(o.z)}, ib{NB(inv.x), NB(inv.y), NB(inv.z)};
    alignas(64) float tn_out[accel::kNodeWidth];
    for (std::size_t j = 0; j < std::size_t(accel::kNodeWidth); j += NW) {
        NB tn;
        const auto hit = slab_test(NB::load_aligned(n.lo_x + j), NB::load_aligned(n.lo_y + j),
                                   NB::load_aligned(n.lo_z + j), NB::load_aligned(n.hi_x + j),
                                   NB::load_aligned(n.hi_y + j), NB::load_aligned(n.hi_z + j), ob, ib, NB(t_max), tn);
        xsimd::select(hit, tn, NB(kInfF)).store_aligned(tn_out + j);
    }
    int nh = 0;
    for (int j = 0; j < accel::kNodeWidth; ++j)
        if (tn_out[j] < kInfF && n.child[j] >= 0) {
            if (n.count[j] > 0) prefetch_leaf(bvh, n.child[j], n.count[j]);
            hits[nh++] = {n.child[j], n.count[j], tn_out[j]};
        }
    return nh;
}

template <class Arch, class NodeArch>
void bvh_closest_single(const AccelView& bvh, RayView rays, std::int32_t* object) {
    const simd::FlushDenormals ftz;  // see simd/lanes.h
    using namespace accel_detail;
    StackEntry stack[kStack];
    for (std::size_t i = 0; i < rays.count; ++i) {
        float best = rays.t_max[i];
        if (!(best > 0.f)) continue;
        const Vec3f o{rays.ox[i], rays.oy[i], rays.oz[i]}, d{rays.dx[i], rays.dy[i], rays.dz[i]};
        const Vec3f inv{1.f / d.x, 1.f / d.y, 1.f / d.z};
        std::int32_t best_id = -1;
        int sp = 0;
        stack[sp++] = {0, 0, 0.f};
        while (sp > 0) {
            const StackEntry e = stack[--sp];
            if (e.t > best) continue;
            if (e.count > 0) {
                for (std::uint32_t k = e.child; k < e.child + e.count; ++k) {
                    const KernelObject& ob = bvh.prims[k];
                    if (ob.xf.kind == std::uint32_t(ShapeKind::Mesh)) {
                        const float t = mesh_single_closest<Arch>(rays, i, o, d, ob.xf, best);
                        if (t < best) {
                            best = t;
                            best_id = ob.xf.id;
                        }
                        continue;
                    }
                    with_shape(ob.xf.kind, [&](auto shape) {
                        const float t = object_t_single<Arch, decltype(shape)>(o, d, ob.xf, best);
                        if (t < best) {
                            best = t;
                            best_id = ob.xf.id;
                        }
                    });
                }
                continue;
            }
            StackEntry hits[accel::kNodeWidth];
            const int nh = node_hits_single<NodeArch>(bvh, bvh.nodes[e.child], o, inv, best, hits);
            push_sorted(stack, sp, hits, nh);
        }
        if (best_id >= 0) {
            rays.t_max[i] = best;
            object[i] = best_id;
        }
    }
}

template <class Arch, class NodeArch>
void bvh_any_single(const AccelView& bvh, RayView rays) {
    const simd::FlushDenormals ftz;  // see simd/lanes.h
    using namespace accel_detail;
    StackEntry stack[kStack];
    for (std::size_t i = 0; i < rays.count; ++i) {
        const float t_max = rays.t_max[i];
        if (!(t_max > 0.f)) continue;
        const Vec3f o{rays.ox[i], rays.oy[i], rays.oz[i]}, d{rays.dx[i], rays.dy[i], rays.dz[i]};
        const Vec3f inv{1.f / d.x, 1.f / d.y, 1.f / d.z};
        bool blocked = false;
        int sp = 0;
        stack[sp++] = {0, 0, 0.f};
        while (sp > 0 && !blocked) {
            const StackEntry e = stack[--sp];
            if (e.count > 0) {
                for (std::uint32_t k = e.child; k < e.child + e.count && !blocked; ++k) {
                    const KernelObject& ob = bvh.prims[k];
                    if (ob.xf.kind == std::uint32_t(ShapeKind::Mesh)) {
                        blocked = mesh_single_any<Arch>(o, d, ob.xf, t_max);
                        continue;
                    }
                    with_shape(ob.xf.kind, [&](auto shape) {
                        blocked = object_t_single<Arch, decltype(shape)>(o, d, ob.xf, t_max) < t_max;
                    });
                }
                continue;
            }
            StackEntry hits[accel::kNodeWidth];
            const int nh = node_hits_single<NodeArch>(bvh, bvh.nodes[e.child], o, inv, t_max, hits);
            for (int k = 0; k < nh; ++k) stack[sp++] = hits[k];
        }
        if (blocked) rays.t_max[i] = 0.f;
    }
}

template <class Arch, class NodeArch>
AccelKernelTable make_accel_table() {
    return AccelKernelTable{&bvh_closest_packet<Arch>, &bvh_any_packet<Arch>, &bvh_closest_single<Arch, NodeArch>,
                            &bvh_any_single<Arch, NodeArch>};
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
