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

/// The spans of object `ob`'s shapes (each one slot: an object without meshes) over a
/// packet's lanes into `line`, and the slots some lane's line meets, ascending, into `live`
/// (their count returned). A packet that misses a shape's box over (0, t_max) takes the span
/// as empty in every lane without its math (CsgView::shape_boxes).
template <class B>
inline int csg_packet_spans(const CsgView& csg, const CsgObjectView& ob, const RayPacket<B>& r, const Vec3T<B>& inv,
                            const B& t_max, CsgLine<B>& line, std::uint8_t* live) {
    int n = 0;
    for (int s = 0; s < ob.layout.shapes; ++s) {
        const std::uint32_t k = ob.layout.first_shape + std::uint32_t(s);
        if (csg.shape_bounded[k] && !packet_meets_box<B, float>(r, inv, csg.shape_boxes[k], t_max)) {
            line.enter[std::size_t(s)] = B(std::numeric_limits<float>::infinity());
            line.exit[std::size_t(s)] = B(-std::numeric_limits<float>::infinity());
            continue;
        }
        const ObjectXf& xf = csg.records[k].xf;
        const RayPacket<B> c = to_canonical<B, float>(r, xf);
        const SpanT<B> span = csg_shape_span<B>(ShapeKind(xf.kind), c.o, c.d, B(xf.param));
        line.enter[std::size_t(s)] = span.enter;
        line.exit[std::size_t(s)] = span.exit;
        if (xsimd::any(span.enter < span.exit)) live[n++] = std::uint8_t(s);
    }
    return n;
}

/// A boundary of a two-shape result in lanes: t (+inf: none), whether it is the second
/// shape's and whether its normal is turned round.
template <class B>
struct PairBoundary {
    using M = xsimd::batch_bool<float, typename B::arch_type>;
    B t;
    M second, flip;
};

/// The first boundary with t > 0 of `op` over two shapes of spans [e0, x0], [e1, x1] (each
/// empty unless enter < exit), in lanes, in closed form: what render/csg_spans.h's walk
/// (csg_first_boundary) gives, tie rules included (touching spans join, coinciding ends show
/// the first shape's surface), from comparisons of the same values, so the same bits. The
/// result has at most two spans, [o1, c1] and [o2, c2], in order; the earliest valid end past
/// 0 is taken.
template <class B>
inline PairBoundary<B> csg_pair_boundary(CsgOp op, const B& e0, const B& x0, const B& e1, const B& x1) {
    using M = typename PairBoundary<B>::M;
    const B inf(std::numeric_limits<float>::infinity()), zero(0.f);
    const M no(false), yes(true);
    const M a = e0 < x0, b = e1 < x1;             // false on NaN: a miss
    PairBoundary<B> o1{e0, no, no}, c1{x0, no, no}, o2{x1, yes, no}, c2{x0, no, no};
    M v1 = no, v2 = no;
    switch (op) {
        case CsgOp::Intersection: {
            // Opens at the later entry, closes at the first exit (the first's on a tie);
            // nothing when that is not after the opening.
            const M later = e0 < e1, first = x0 <= x1;
            o1 = {xsimd::select(later, e1, e0), later, no};
            c1 = {xsimd::select(first, x0, x1), !first, no};
            v1 = a && b && (c1.t > o1.t);
            break;
        }
        case CsgOp::Difference: {
            // The second shape's boundaries are turned round. inside: the first enters within
            // the second (entering together included); cut: the second enters within the
            // first. Either way the part after the second's exit remains when that is before
            // the first's.
            const M inside = b && (e1 <= e0) && (e0 < x1), cut = b && !inside && (e0 < e1) && (e1 < x0);
            c1 = {xsimd::select(cut, e1, x0), cut, cut};
            v1 = a && !inside;
            o2 = {x1, yes, yes};
            v2 = a && (inside || cut) && (x1 < x0);
            break;
        }
        case CsgOp::Union:
        case CsgOp::Merge: {
            // The first to enter opens; overlapping or touching spans close at the later exit
            // (the first's on a tie), apart ones stay two.
            const M a_first = a && (!b || (e0 <= e1));
            const M overlap = a && b && ((a_first && (e1 <= x0)) || (!a_first && (e0 <= x1)));
            const M later = x1 > x0;
            o1 = {xsimd::select(a_first, e0, e1), !a_first, no};
            c1 = {xsimd::select(overlap, xsimd::select(later, x1, x0), xsimd::select(a_first, x0, x1)),
                  (overlap && later) || (!overlap && !a_first), no};
            v1 = a || b;
            o2 = {xsimd::select(a_first, e1, e0), a_first, no};
            c2 = {xsimd::select(a_first, x1, x0), a_first, no};
            v2 = a && b && !overlap;
            break;
        }
    }
    // The earliest end past 0: taken from the last to the first, each earlier one replacing.
    PairBoundary<B> r{inf, no, no};
    const auto take = [&](const PairBoundary<B>& c, const M& valid) {
        const M m = valid && (c.t > zero);
        r = {xsimd::select(m, c.t, r.t), (m && c.second) || (!m && r.second), (m && c.flip) || (!m && r.flip)};
    };
    take(c2, v2);
    take(o2, v2);
    take(c1, v1);
    take(o1, v1);
    return r;
}

/// Closest (kAny false: t_max and object[] of the rays whose first CSG surface in
/// (0, t_max) is closer) or any hit (t_max = 0 for the rays a CSG result blocks).
template <class Arch, bool kAny>
void csg_hits(const CsgView& csg, RayView rays, std::int32_t* object) {
    using B = xsimd::batch<float, Arch>;
    using M = xsimd::batch_bool<float, Arch>;
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;
    CsgLine<B> line;
    std::array<std::uint8_t, kMaxCsgShapes> live;
    for (std::size_t i = 0; i < rays.count; i += W) {  // padding makes the last packet safe
        B t_max = load_lanes<B>(rays.t_max + i);
        if (!xsimd::any(t_max > B(0.f))) continue;  // padding, or blocked already
        const RayPacket<B> r{{load_lanes<B>(rays.ox + i), load_lanes<B>(rays.oy + i), load_lanes<B>(rays.oz + i)},
                             {load_lanes<B>(rays.dx + i), load_lanes<B>(rays.dy + i), load_lanes<B>(rays.dz + i)}};
        const Vec3T<B> inv{B(1.f) / r.d.x, B(1.f) / r.d.y, B(1.f) / r.d.z};
        const std::size_t lanes = std::min(W, rays.count - i);
        for (std::size_t k = 0; k < csg.count; ++k) {
            const CsgObjectView& ob = csg.objects[k];
            if (ob.bounded && !packet_meets_box<B, float>(r, inv, ob.box, t_max)) continue;
            if (ob.scalar) {  // an object with a mesh: each lane whole, in scalar code
                // Per lane, the shapes whose box its segment (0, t_max) misses: their spans are
                // taken as empty (a mesh's walk saved), which changes no boundary inside the
                // segment; a lane that misses the object's box is skipped whole.
                alignas(64) float meets[simd::kMaxLanes];
                const auto in_box = ob.bounded ? lanes_meeting_box<B, float>(r, inv, ob.box, t_max) : (t_max > B(0.f));
                xsimd::select(in_box, B(1.f), B(0.f)).store_aligned(meets);
                std::uint64_t empty[simd::kMaxLanes] = {};
                for (int s = 0; s < ob.layout.shapes; ++s) {
                    const std::uint32_t shape = ob.layout.first_shape + std::uint32_t(s);
                    if (!csg.shape_bounded[shape]) continue;
                    alignas(64) float shape_meets[simd::kMaxLanes];
                    xsimd::select(lanes_meeting_box<B, float>(r, inv, csg.shape_boxes[shape], t_max), B(1.f), B(0.f))
                        .store_aligned(shape_meets);
                    for (std::size_t l = 0; l < lanes; ++l)
                        if (shape_meets[l] == 0.f) empty[l] |= std::uint64_t(1) << s;
                }
                for (std::size_t l = 0; l < lanes; ++l) {
                    float& t = rays.t_max[i + l];
                    if (!(t > 0.f) || meets[l] == 0.f) continue;
                    const float o[3] = {rays.ox[i + l], rays.oy[i + l], rays.oz[i + l]};
                    const float d[3] = {rays.dx[i + l], rays.dy[i + l], rays.dz[i + l]};
                    std::int32_t id = 0;
                    const bool want_prim = !kAny && rays.prim;
                    if (!csg_scalar_lane(csg, ob, o, d, empty[l], t, id, want_prim ? rays.prim + i + l : nullptr,
                                         want_prim ? rays.bu + i + l : nullptr, want_prim ? rays.bv + i + l : nullptr))
                        continue;
                    if constexpr (kAny) t = 0.f;
                    else object[i + l] = id;
                }
                t_max = load_lanes<B>(rays.t_max + i);
                if (kAny && !xsimd::any(t_max > B(0.f))) break;
                continue;
            }
            const int live_count = csg_packet_spans(csg, ob, r, inv, t_max, line, live.data());
            if (live_count == 0) continue;
            // The first boundary per lane: the shape (relative to the object's first) and
            // whether its normal is turned round.
            B t, shape;
            M flip;
            if (ob.pair) {  // a root of two shapes, in closed form
                const PairBoundary<B> at = csg_pair_boundary(ob.op, line.enter[0], line.exit[0], line.enter[1], line.exit[1]);
                t = at.t;
                shape = xsimd::select(at.second, B(1.f), B(0.f));
                flip = at.flip;
            } else {  // any tree: the walk along the line, in lanes
                const CsgFirst<B> at =
                    csg_first_boundary(csg.nodes, ob.root, ob.layout, line, live.data(), live_count, B(0.f), t_max);
                t = at.t;
                shape = at.slot;  // one slot per shape
                flip = !simd::mask_xor(at.at_exit, at.entering);
            }
            const M hit = t < t_max;  // false for padding and blocked lanes (t_max <= 0 < t)
            if (!xsimd::any(hit)) continue;
            if constexpr (kAny) {
                t_max = xsimd::select(hit, B(0.f), t_max);
            } else {
                t_max = xsimd::select(hit, t, t_max);
                alignas(64) float slot[simd::kMaxLanes], turned[simd::kMaxLanes];
                xsimd::select(hit, shape, B(-1.f)).store_aligned(slot);
                xsimd::select(flip, B(1.f), B(0.f)).store_aligned(turned);
                const std::int32_t base = csg.first_id + std::int32_t(ob.layout.first_shape);
                for (std::size_t l = 0; l < lanes; ++l)
                    if (slot[l] >= 0.f)
                        object[i + l] = base + std::int32_t(slot[l]) + (turned[l] != 0.f ? csg.shapes : 0);
            }
            alignas(64) float out[simd::kMaxLanes];
            t_max.store_aligned(out);
            for (std::size_t l = 0; l < lanes; ++l) rays.t_max[i + l] = out[l];
            if (kAny && !xsimd::any(t_max > B(0.f))) break;  // the whole packet is in shadow
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
