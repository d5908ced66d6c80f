#pragma once
// CSG objects in SIMD (docs/architecture.md, "CSG"): each shape's span over a packet's lanes
// (shapes/solid_span.h with V = a batch, the same template the recursive engine runs in
// double), then the first boundary of the result in lanes: in closed form for a root of two
// shapes, else by the walk along the line (render/csg_spans.h, csg_first_boundary, the
// recursive engine's own code with V = a batch). Included only by kernels/intersect_kernel.h.
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <array>
#include <limits>

#include "kernels/csg_view.h"
#include "kernels/ray_stream.h"
#include "render/csg_spans.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// Per lane and slot of a packet, a mesh slot's ends (the walk's `CsgSlotEnds`).
using CsgLaneEnds = CsgSlotEnds[kMaxCsgShapes][simd::kMaxLanes];

/// A closed mesh's spans along each line of a packet (o, d: the packet in the mesh's
/// canonical space; `lanes`: the lanes wanted) into the slots [first, first +
/// kMeshCsgSpans) of `line` and `ends`: per lane what mesh_slot_spans gives, by one walk of the
/// packet. Each lane's line starts where it enters the mesh's box, computed as mesh_crossings
/// does; a triangle's test is the same arithmetic in every lane; the padded boxes never drop a
/// leaf a line crosses in, and the crossings are kept in an order of their own (t, then
/// triangle): so the same crossings, the same bits, as the scalar walk.
template <class B, class M>
inline void mesh_packet_slots(const Mesh& mesh, const Vec3T<B>& o, const Vec3T<B>& d, const M& lanes,
                              CsgLine<B>& line, CsgLaneEnds& ends, int first) {
    constexpr std::size_t W = B::size;
    const B inf(std::numeric_limits<float>::infinity());
    alignas(64) float enter[kMeshCsgSpans][simd::kMaxLanes], exit[kMeshCsgSpans][simd::kMaxLanes];
    for (int j = 0; j < kMeshCsgSpans; ++j) {
        inf.store_aligned(enter[j]);
        (-inf).store_aligned(exit[j]);
    }
    const auto store = [&] {
        for (int j = 0; j < kMeshCsgSpans; ++j) {
            line.enter[std::size_t(first + j)] = B::load_aligned(enter[j]);
            line.exit[std::size_t(first + j)] = B::load_aligned(exit[j]);
        }
    };
    const MeshView m = mesh.view();
    if (m.n_tris == 0 || mesh.bvh.empty()) return store();
    // The line's stretch through the mesh's box, over every t (mesh_crossings' steps).
    B t0 = -inf, t1 = inf;
    M in_box(true);
    const B os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    for (int a = 0; a < 3; ++a) {
        const B lo(float(mesh.bvh.bounds.lo[a])), hi(float(mesh.bvh.bounds.hi[a]));
        const M flat = ds[a] == B(0.f);
        in_box = in_box && !(flat && ((os[a] < lo) || (os[a] > hi)));
        const B ta = (lo - os[a]) / ds[a], tb = (hi - os[a]) / ds[a];
        const B near = xsimd::select(tb < ta, tb, ta), far = xsimd::select(ta < tb, tb, ta);
        t0 = xsimd::select(flat, t0, xsimd::select(t0 < near, near, t0));
        t1 = xsimd::select(flat, t1, xsimd::select(far < t1, far, t1));
    }
    in_box = in_box && (t0 <= t1);
    const M walking = lanes && in_box;
    const std::uint32_t walk = lane_bits(walking);
    if (walk == 0) return store();
    // Lanes outside the walk get a harmless start (their results are not read).
    const B t0w = xsimd::select(walking, t0, B(0.f)), t1w = xsimd::select(walking, t1, B(0.f));
    const Vec3T<B> start = o + d * t0w;
    const WatertightRay<B> wr = watertight_ray(start, d);
    const Vec3T<B> inv{B(1.f) / d.x, B(1.f) / d.y, B(1.f) / d.z};
    const B reach = (t1w - t0w) * B(1.0001f) + B(1e-6f);
    MeshCrossing<float> cross[simd::kMaxLanes][kMeshCsgCrossings];
    int count[simd::kMaxLanes] = {};
    std::uint32_t stack[accel::kNodeWidth * 64], stack_count[accel::kNodeWidth * 64];
    int sp = 0;
    stack[sp] = 0;
    stack_count[sp++] = 0;
    alignas(64) float t_at[simd::kMaxLanes], enters_at[simd::kMaxLanes];
    while (sp > 0) {
        --sp;
        const std::uint32_t c = stack[sp], cnt = stack_count[sp];
        if (cnt == 0) {
            const accel::WideNode& n = m.nodes[c];
            for (int j = 0; j < accel::kNodeWidth; ++j) {
                if (n.child[j] < 0) continue;
                B tn;
                if (!xsimd::any(mesh_detail::robust_box(n, j, start, inv, reach, tn) && walking)) continue;
                stack[sp] = std::uint32_t(n.child[j]);
                stack_count[sp++] = n.count[j];
            }
            continue;
        }
        for (std::uint32_t k = c; k < c + cnt; ++k) {
            using mesh_detail::vertex;
            const Vec3T<B> p0 = vertex<B>(m, k, 0), p1 = vertex<B>(m, k, 1), p2 = vertex<B>(m, k, 2);
            const TriangleHit<B> h = triangle_hit(wr, p0, p1, p2, -inf, inf);
            const M hit = walking && (h.t < inf);
            if (!xsimd::any(hit)) continue;
            (t0w + h.t).store_aligned(t_at);
            xsimd::select(dot(d, triangle_normal(p0, p1, p2)) < B(0.f), B(1.f), B(0.f)).store_aligned(enters_at);
            alignas(64) float hits[simd::kMaxLanes];
            xsimd::select(hit, B(1.f), B(0.f)).store_aligned(hits);
            for (std::size_t l = 0; l < W; ++l) {
                if (hits[l] == 0.f) continue;
                const MeshCrossing<float> x{t_at[l], k, enters_at[l] != 0.f};
                keep_crossing(cross[l], count[l], kMeshCsgCrossings, x);
            }
        }
    }
    for (std::size_t l = 0; l < W; ++l)
        if (walk >> l & 1u)
            mesh_winding_spans(cross[l], count[l], &enter[0][l], &exit[0][l], &ends[first][l], simd::kMaxLanes);
    store();
}

/// A torus's two spans along each line of a packet (o, d: its canonical space) into the slots
/// [first, first + 2): torus_spans in double lanes, two or more double batches to a float
/// one, each lane rounded to float as the scalar walk's (torus_slot_spans).
template <class B>
inline void torus_packet_slots(const Vec3T<B>& o, const Vec3T<B>& d, float minor, CsgLine<B>& line, int first) {
    using D = xsimd::batch<double, typename B::arch_type>;
    constexpr std::size_t W = B::size, WD = D::size;
    alignas(64) float in[6][simd::kMaxLanes], out[4][simd::kMaxLanes];
    const B parts[6] = {o.x, o.y, o.z, d.x, d.y, d.z};
    for (int k = 0; k < 6; ++k) parts[k].store_aligned(in[k]);
    for (std::size_t h = 0; h < W; h += WD) {
        const auto wide = [&](int k) { return D::load_unaligned(in[k] + h); };  // float -> double
        const std::array<SpanT<D>, 2> s =
            torus_spans<D>({wide(0), wide(1), wide(2)}, {wide(3), wide(4), wide(5)}, D(double(minor)));
        s[0].enter.store_unaligned(out[0] + h);  // double -> float, rounded to nearest
        s[0].exit.store_unaligned(out[1] + h);
        s[1].enter.store_unaligned(out[2] + h);
        s[1].exit.store_unaligned(out[3] + h);
    }
    for (std::size_t j = 0; j < 2; ++j) {
        line.enter[std::size_t(first) + j] = B::load_aligned(out[2 * j]);
        line.exit[std::size_t(first) + j] = B::load_aligned(out[2 * j + 1]);
    }
}

/// The spans of object `ob`'s shapes over a packet's lanes into `line` (a mesh's into its
/// slots, their ends into `ends`), and the slots some lane's line meets, ascending, into
/// `live` (their count returned). A packet that misses a shape's box over (0, t_max) takes the
/// span as empty in every lane without its math (CsgView::shape_boxes); a mesh is walked for
/// the lanes that meet its box.
template <class B>
inline int csg_packet_spans(const CsgView& csg, const CsgObjectView& ob, const RayPacket<B>& r, const Vec3T<B>& inv,
                            const B& t_max, CsgLine<B>& line, CsgLaneEnds& ends, std::uint8_t* live) {
    int n = 0;
    for (int s = 0; s < ob.layout.shapes; ++s) {
        const std::uint32_t k = ob.layout.first_shape + std::uint32_t(s);
        const int first = ob.layout.first_slot[std::size_t(s)], last = ob.layout.first_slot[std::size_t(s) + 1];
        const auto meets = csg.shape_bounded[k] ? lanes_meeting_box<B, float>(r, inv, csg.shape_boxes[k], t_max)
                                                : (t_max > B(0.f));
        if (!xsimd::any(meets)) {
            for (int j = first; j < last; ++j) {
                line.enter[std::size_t(j)] = B(std::numeric_limits<float>::infinity());
                line.exit[std::size_t(j)] = B(-std::numeric_limits<float>::infinity());
            }
            continue;
        }
        const ObjectXf& xf = csg.records[k].xf;
        const RayPacket<B> c = to_canonical<B, float>(r, xf);
        if (const Mesh* mesh = csg.meshes[k]) {
            mesh_packet_slots(*mesh, c.o, c.d, meets, line, ends, first);
        } else if (ShapeKind(xf.kind) == ShapeKind::Torus) {
            torus_packet_slots(c.o, c.d, xf.param, line, first);
        } else {
            const SpanT<B> span = csg_shape_span<B>(ShapeKind(xf.kind), c.o, c.d, B(xf.param));
            line.enter[std::size_t(first)] = span.enter;
            line.exit[std::size_t(first)] = span.exit;
        }
        for (int j = first; j < last; ++j)
            if (xsimd::any(line.enter[std::size_t(j)] < line.exit[std::size_t(j)])) live[n++] = std::uint8_t(j);
    }
    return n;
}

/// A boundary of a two-shape result in lanes: t (+inf: none), whether it is the second
/// shape's, whether it is that shape's exit, and whether the line enters the result there.
template <class B>
struct PairBoundary {
    using M = xsimd::batch_bool<float, typename B::arch_type>;
    B t;
    M second, exit, entering;
};

/// The first boundary with t > 0 of `op` over two shapes of spans [e0, x0], [e1, x1] (each
/// empty unless enter < exit), in lanes, in closed form: what render/csg_spans.h's walk
/// (csg_first_boundary) gives, tie rules included (touching spans join, coinciding ends show
/// the first shape's surface), from comparisons of the same values, so the same bits. A
/// union's boundaries are every end (its inner surfaces); another result has at most two
/// spans, [o1, c1] and [o2, c2], in order, and the earliest valid end past 0 is taken.
template <class B>
inline PairBoundary<B> csg_pair_boundary(CsgOp op, const B& e0, const B& x0, const B& e1, const B& x1) {
    using M = typename PairBoundary<B>::M;
    const B inf(std::numeric_limits<float>::infinity()), zero(0.f);
    const M no(false), yes(true);
    const M a = e0 < x0, b = e1 < x1;             // false on NaN: a miss
    // Each boundary: t, whether it is the second shape's, whether that shape's exit, whether
    // the line enters the result there.
    PairBoundary<B> o1{e0, no, no, yes}, c1{x0, no, yes, no}, o2{x1, yes, yes, yes}, c2{x0, no, yes, no};
    M v1 = no, v2 = no;
    switch (op) {
        case CsgOp::Intersection: {
            // Opens at the later entry, closes at the first exit (the first's on a tie);
            // nothing when that is not after the opening.
            const M later = e0 < e1, first = x0 <= x1;
            o1 = {xsimd::select(later, e1, e0), later, no, yes};
            c1 = {xsimd::select(first, x0, x1), !first, yes, no};
            v1 = a && b && (c1.t > o1.t);
            break;
        }
        case CsgOp::Difference: {
            // The second shape's boundaries are turned round. inside: the first enters within
            // the second (entering together included); cut: the second enters within the
            // first. Either way the part after the second's exit remains when that is before
            // the first's.
            const M inside = b && (e1 <= e0) && (e0 < x1), cut = b && !inside && (e0 < e1) && (e1 < x0);
            c1 = {xsimd::select(cut, e1, x0), cut, !cut, no};
            v1 = a && !inside;
            o2 = {x1, yes, yes, yes};
            v2 = a && (inside || cut) && (x1 < x0);
            break;
        }
        case CsgOp::Union: {
            // Every end of either shape is a surface (the inner ones too): the earliest past
            // 0, the first shape's on a tie; the line enters the result's side of it at an
            // enter.
            PairBoundary<B> r{inf, no, no, no};
            const auto earlier = [&](const B& t, const M& valid, const M& second, const M& exit) {
                const M m = valid && (t > zero) && (t <= r.t);
                r = {xsimd::select(m, t, r.t), mask_select(m, second, r.second), mask_select(m, exit, r.exit),
                     mask_select(m, !exit, r.entering)};
            };
            earlier(x1, b, yes, yes);  // the first shape's last, so that it wins ties
            earlier(e1, b, yes, no);
            earlier(x0, a, no, yes);
            earlier(e0, a, no, no);
            return r;
        }
        case CsgOp::Merge: {
            // The first to enter opens; overlapping or touching spans close at the later exit
            // (the first's on a tie), apart ones stay two.
            const M a_first = a && (!b || (e0 <= e1));
            const M overlap = a && b && ((a_first && (e1 <= x0)) || (!a_first && (e0 <= x1)));
            const M later = x1 > x0;
            o1 = {xsimd::select(a_first, e0, e1), !a_first, no, yes};
            c1 = {xsimd::select(overlap, xsimd::select(later, x1, x0), xsimd::select(a_first, x0, x1)),
                  (overlap && later) || (!overlap && !a_first), yes, no};
            v1 = a || b;
            o2 = {xsimd::select(a_first, e1, e0), a_first, no, yes};
            c2 = {xsimd::select(a_first, x1, x0), a_first, yes, no};
            v2 = a && b && !overlap;
            break;
        }
    }
    // The earliest end past 0: taken from the last to the first, each earlier one replacing.
    PairBoundary<B> r{inf, no, no, no};
    const auto take = [&](const PairBoundary<B>& c, const M& valid) {
        const M m = valid && (c.t > zero);
        r = {xsimd::select(m, c.t, r.t), mask_select(m, c.second, r.second), mask_select(m, c.exit, r.exit),
             mask_select(m, c.entering, r.entering)};
    };
    take(c2, v2);
    take(o2, v2);
    take(c1, v1);
    take(o1, v1);
    return r;
}

/// One CSG object against the packet at ray i (`lanes` of them real; r, inv its rays): the
/// lanes whose first surface of the object's result in (0, t_max) comes first take it (t_max
/// and object[]; kAny: t_max = 0). Always inlined: called, it made the intersect stage of
/// one-object scenes 3 - 5% slower (die, pipe, tree at 1280x720, 9 runs).
template <class Arch, bool kAny>
[[gnu::always_inline]] inline void csg_object_hits(const CsgView& csg, const CsgObjectView& ob, RayView rays,
                                                   std::int32_t* object, std::size_t i, std::size_t lanes,
                                                   const RayPacket<xsimd::batch<float, Arch>>& r,
                                                   const Vec3T<xsimd::batch<float, Arch>>& inv,
                                                   xsimd::batch<float, Arch>& t_max,
                                                   CsgLine<xsimd::batch<float, Arch>>& line, CsgLaneEnds& ends,
                                                   std::uint8_t* live) {
    using B = xsimd::batch<float, Arch>;
    using M = xsimd::batch_bool<float, Arch>;
    if (ob.bounded && !packet_meets_box<B, float>(r, inv, ob.box, t_max)) return;
    const int live_count = csg_packet_spans(csg, ob, r, inv, t_max, line, ends, live);
    if (live_count == 0) return;
    // The first boundary per lane: its slot and whether the line enters the result there.
    B t, slot;
    M at_exit, entering;
    if (ob.pair) {  // a root of two shapes, in closed form
        const PairBoundary<B> at =
            csg_pair_boundary(ob.op, line.enter[0], line.exit[0], line.enter[1], line.exit[1]);
        t = at.t;
        slot = xsimd::select(at.second, B(1.f), B(0.f));
        at_exit = at.exit;
        entering = at.entering;
    } else {  // any tree: the walk along the line, in lanes
        const CsgFirst<B> at =
            csg_first_boundary(csg.nodes, ob.root, ob.layout, line, live, live_count, B(0.f), t_max,
                               ob.inner_surfaces);
        t = at.t;
        slot = at.slot;
        at_exit = at.at_exit;
        entering = at.entering;
    }
    const M hit = t < t_max;  // false for padding and blocked lanes (t_max <= 0 < t)
    if (!xsimd::any(hit)) return;
    if constexpr (kAny) {
        t_max = xsimd::select(hit, B(0.f), t_max);
    } else {
        t_max = xsimd::select(hit, t, t_max);
        if (!ob.multi_slot) {  // one slot per shape, and no turned ends: csg_flip in lanes
            alignas(64) float slots[simd::kMaxLanes], flips[simd::kMaxLanes];
            xsimd::select(hit, slot, B(-1.f)).store_aligned(slots);
            xsimd::select(simd::mask_xor(at_exit, entering), B(0.f), B(1.f)).store_aligned(flips);
            const std::int32_t base = csg.first_id + std::int32_t(ob.layout.first_shape);
            for (std::size_t l = 0; l < lanes; ++l)
                if (slots[l] >= 0.f)
                    object[i + l] = base + std::int32_t(slots[l]) + (flips[l] != 0.f ? csg.shapes : 0);
        } else {  // slots mapped back to shapes; a mesh's ends keep their triangle and turn
            alignas(64) float slots[simd::kMaxLanes], exits[simd::kMaxLanes], enters[simd::kMaxLanes];
            xsimd::select(hit, slot, B(-1.f)).store_aligned(slots);
            xsimd::select(at_exit, B(1.f), B(0.f)).store_aligned(exits);
            xsimd::select(entering, B(1.f), B(0.f)).store_aligned(enters);
            for (std::size_t l = 0; l < lanes; ++l) {
                if (slots[l] < 0.f) continue;
                const auto j = std::size_t(slots[l]);
                const std::uint32_t shape = ob.layout.first_shape + ob.layout.shape_of[j];
                const int end = exits[l] != 0.f ? 1 : 0;
                const Mesh* mesh = csg.meshes[shape];
                const bool turned = mesh && ends[j][l].turned[std::size_t(end)];
                object[i + l] = csg.first_id + std::int32_t(shape) +
                                (csg_flip(end == 1, enters[l] != 0.f, turned) ? csg.shapes : 0);
                if (mesh && rays.prim) {  // the triangle, and where on it (found again)
                    const std::uint32_t tri = ends[j][l].tri[std::size_t(end)];
                    const ObjectXf& xf = csg.records[shape].xf;
                    const Vec3f ow{rays.ox[i + l], rays.oy[i + l], rays.oz[i + l]};
                    const Vec3f dw{rays.dx[i + l], rays.dy[i + l], rays.dz[i + l]};
                    rays.prim[i + l] = std::int32_t(tri);
                    mesh_crossing_uv(mesh->view(), tri, apply_point(xf.m, ow), apply_vector(xf.m, dw),
                                     rays.bu[i + l], rays.bv[i + l]);
                }
            }
        }
    }
    alignas(64) float out[simd::kMaxLanes];
    t_max.store_aligned(out);
    for (std::size_t l = 0; l < lanes; ++l) rays.t_max[i + l] = out[l];
}

/// Closest (kAny false: t_max and object[] of the rays whose first CSG surface in
/// (0, t_max) is closer; on a mesh also prim, bu, bv) or any hit (t_max = 0 for the rays a
/// CSG result blocks). Per packet, the objects of the CSG hierarchy whose boxes it meets
/// within its t_max so far (CsgView::tree), or every object in a list.
template <class Arch, bool kAny>
void csg_hits(const CsgView& csg, RayView rays, std::int32_t* object) {
    using B = xsimd::batch<float, Arch>;
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;
    CsgLine<B> line;
    CsgLaneEnds ends;
    std::array<std::uint8_t, kMaxCsgShapes> live;
    constexpr int kStack = accel::kNodeWidth * 64;
    std::uint32_t stack_child[kStack], stack_count[kStack];
    for (std::size_t i = 0; i < rays.count; i += W) {  // padding makes the last packet safe
        B t_max = load_lanes<B>(rays.t_max + i);
        if (!xsimd::any(t_max > B(0.f))) continue;  // padding, or blocked already
        const RayPacket<B> r{{load_lanes<B>(rays.ox + i), load_lanes<B>(rays.oy + i), load_lanes<B>(rays.oz + i)},
                             {load_lanes<B>(rays.dx + i), load_lanes<B>(rays.dy + i), load_lanes<B>(rays.dz + i)}};
        const Vec3T<B> inv{B(1.f) / r.d.x, B(1.f) / r.d.y, B(1.f) / r.d.z};
        const std::size_t lanes = std::min(W, rays.count - i);
        // True once the whole packet is in shadow (any hit): the rest can be skipped.
        const auto visit = [&](const CsgObjectView& ob) {
            csg_object_hits<Arch, kAny>(csg, ob, rays, object, i, lanes, r, inv, t_max, line, ends, live.data());
            return kAny && !xsimd::any(t_max > B(0.f));
        };
        if (!csg.tree) {
            for (std::size_t k = 0; k < csg.count; ++k)
                if (visit(csg.objects[k])) break;
            continue;
        }
        bool done = false;
        for (std::size_t u = 0; u < csg.tree_unbounded_count && !done; ++u)
            done = visit(csg.objects[csg.tree_unbounded[u]]);
        if (!csg.tree_nodes) continue;
        int sp = 0;
        stack_child[sp] = 0;
        stack_count[sp++] = 0;
        while (sp > 0 && !done) {
            --sp;
            const std::uint32_t c = stack_child[sp], cnt = stack_count[sp];
            if (cnt > 0) {
                for (std::uint32_t k = c; k < c + cnt && !done; ++k) done = visit(csg.objects[csg.tree_prims[k]]);
                continue;
            }
            const accel::WideNode& n = csg.tree_nodes[c];
            for (int j = 0; j < accel::kNodeWidth; ++j) {
                if (n.child[j] < 0) continue;
                const ObjectBounds box{{n.lo_x[j], n.lo_y[j], n.lo_z[j]}, {n.hi_x[j], n.hi_y[j], n.hi_z[j]}};
                if (!packet_meets_box<B, float>(r, inv, box, t_max)) continue;
                stack_child[sp] = std::uint32_t(n.child[j]);
                stack_count[sp++] = n.count[j];
            }
        }
    }
}

template <class Arch>
void csg_closest(const CsgView& csg, RayView rays, std::int32_t* object) {
    csg_hits<Arch, false>(csg, rays, object);
}
template <class Arch>
void csg_any(const CsgView& csg, RayView rays) {
    csg_hits<Arch, true>(csg, rays, nullptr);
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
