#pragma once
// CSG objects in SIMD (docs/architecture.md, "CSG"): each shape's span over a packet's lanes
// (shapes/solid_span.h with V = a batch, the same template the recursive engine runs in
// double), stored per lane in fixed arrays, then each lane's spans combined node by node
// (render/csg_spans.h with V = float). Included only by kernels/intersect_kernel.h.
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <limits>

#include "kernels/csg_view.h"
#include "kernels/ray_stream.h"
#include "render/csg_spans.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// enter[s][l], exit[s][l]: the span of object `ob`'s shape s along lane l's ray; empty for
/// every lane of a packet that misses the shape's box over (0, t_max) (CsgView::shape_boxes).
template <class B>
inline void csg_packet_spans(const CsgView& csg, const CsgObjectView& ob, const RayPacket<B>& r, const Vec3T<B>& inv,
                             const B& t_max, float (*enter)[simd::kMaxLanes], float (*exit)[simd::kMaxLanes]) {
    for (std::uint32_t s = 0; s < ob.shape_count; ++s) {
        const std::uint32_t k = ob.first_shape + s;
        if (csg.shape_bounded[k] && !packet_meets_box<B, float>(r, inv, csg.shape_boxes[k], t_max)) {
            B(std::numeric_limits<float>::infinity()).store_aligned(enter[s]);
            B(-std::numeric_limits<float>::infinity()).store_aligned(exit[s]);
            continue;
        }
        const ObjectXf& xf = csg.records[k].xf;
        const RayPacket<B> c = to_canonical<B, float>(r, xf);
        const SpanT<B> span = csg_shape_span<B>(ShapeKind(xf.kind), c.o, c.d, B(xf.param));
        span.enter.store_aligned(enter[s]);
        span.exit.store_aligned(exit[s]);
    }
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
/// empty unless enter < exit), in lanes: what render/csg_spans.h's sweep and first_boundary
/// give, tie rule included (at equal t the first shape's boundary is taken first), from the
/// same comparisons of the same values, so the same bits. The result has at most two spans,
/// [o1, c1] and [o2, c2], in order; the earliest valid end past 0 is taken.
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
            // Opens at the later entry (the second's on a tie), closes at the first exit
            // (the first's on a tie); nothing when that is not after the opening.
            const M later = e0 <= e1, first = x0 <= x1;
            o1 = {xsimd::select(later, e1, e0), later, no};
            c1 = {xsimd::select(first, x0, x1), !first, no};
            v1 = a && b && (c1.t > o1.t);
            break;
        }
        case CsgOp::Difference: {
            // The second shape's boundaries are turned round. inside: the first enters within
            // the second; cut: the second enters within the first. Either way the part after
            // the second's exit remains when that is before the first's.
            const M inside = b && (e1 < e0) && (e0 <= x1), cut = b && !inside && (e0 <= e1) && (e1 < x0);
            c1 = {xsimd::select(cut, e1, x0), cut, cut};
            v1 = a && !inside && !(cut && !(e1 > e0));
            o2 = {x1, yes, yes};
            v2 = a && (inside || cut) && (x1 < x0);
            break;
        }
        case CsgOp::Union:
        case CsgOp::Merge: {
            // The first to enter opens; overlapping spans close at the later exit (the
            // second's on a tie), apart ones stay two.
            const M a_first = a && (!b || (e0 <= e1));
            const M overlap = a && b && ((a_first && (e1 < x0)) || (!a_first && (e0 <= x1)));
            const M later = x1 >= x0;
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
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;
    alignas(64) float enter[kMaxCsgShapes][simd::kMaxLanes], exit[kMaxCsgShapes][simd::kMaxLanes];
    CsgSpans<float> spans;
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
                for (std::size_t l = 0; l < lanes; ++l) {
                    float& t = rays.t_max[i + l];
                    if (!(t > 0.f)) continue;
                    const float o[3] = {rays.ox[i + l], rays.oy[i + l], rays.oz[i + l]};
                    const float d[3] = {rays.dx[i + l], rays.dy[i + l], rays.dz[i + l]};
                    std::int32_t id = 0;
                    const bool want_prim = !kAny && rays.prim;
                    if (!csg_scalar_lane(csg, ob, o, d, t, id, want_prim ? rays.prim + i + l : nullptr,
                                         want_prim ? rays.bu + i + l : nullptr, want_prim ? rays.bv + i + l : nullptr))
                        continue;
                    if constexpr (kAny) t = 0.f;
                    else object[i + l] = id;
                }
                t_max = load_lanes<B>(rays.t_max + i);
                if (kAny && !xsimd::any(t_max > B(0.f))) break;
                continue;
            }
            csg_packet_spans(csg, ob, r, inv, t_max, enter, exit);
            if (ob.pair) {  // in lanes
                const PairBoundary<B> at =
                    csg_pair_boundary(ob.op, B::load_aligned(enter[0]), B::load_aligned(exit[0]),
                                      B::load_aligned(enter[1]), B::load_aligned(exit[1]));
                const auto hit = at.t < t_max;  // false for padding and blocked lanes (t_max <= 0 < t)
                if (!xsimd::any(hit)) continue;
                if constexpr (kAny) {
                    t_max = xsimd::select(hit, B(0.f), t_max);
                } else {
                    t_max = xsimd::select(hit, at.t, t_max);
                    alignas(64) float second[simd::kMaxLanes], flip[simd::kMaxLanes];
                    xsimd::select(at.second, B(1.f), B(0.f)).store_aligned(second);
                    xsimd::select(at.flip, B(1.f), B(0.f)).store_aligned(flip);
                    alignas(64) float hits[simd::kMaxLanes];
                    xsimd::select(hit, B(1.f), B(0.f)).store_aligned(hits);
                    for (std::size_t l = 0; l < lanes; ++l)
                        if (hits[l] != 0.f)
                            object[i + l] = csg.first_id + std::int32_t(ob.first_shape) + std::int32_t(second[l]) +
                                            (flip[l] != 0.f ? csg.shapes : 0);
                }
                alignas(64) float out[simd::kMaxLanes];
                t_max.store_aligned(out);
                for (std::size_t l = 0; l < lanes; ++l) rays.t_max[i + l] = out[l];
                if (kAny && !xsimd::any(t_max > B(0.f))) break;
                continue;
            }
            // The combine is a short sweep with branches per boundary: per lane.
            for (std::size_t l = 0; l < lanes; ++l) {
                float& t = rays.t_max[i + l];
                if (!(t > 0.f)) continue;
                csg_node_spans<float>(csg.nodes, ob.root,
                                      [&](std::uint32_t shape) {
                                          const std::uint32_t s = shape - ob.first_shape;
                                          return SpanT<float>{enter[s][l], exit[s][l]};
                                      },
                                      spans);
                const CsgBoundary<float>* at = first_boundary(spans, 0.f, t);
                if (!at) continue;
                if constexpr (kAny) {
                    t = 0.f;
                } else {
                    t = at->t;
                    object[i + l] = csg.first_id + std::int32_t(at->shape) + (at->flip ? csg.shapes : 0);
                }
            }
            t_max = load_lanes<B>(rays.t_max + i);
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
