#pragma once
// CSG objects in SIMD (docs/architecture.md, "CSG"): each shape's span over a packet's lanes
// (shapes/solid_span.h with V = a batch, the same template the recursive engine runs in
// double), stored per lane in fixed arrays, then each lane's spans combined node by node
// (render/csg_spans.h with V = float). Included only by kernels/intersect_kernel.h.
#include <xsimd/xsimd.hpp>

#include <algorithm>

#include "kernels/csg_view.h"
#include "kernels/ray_stream.h"
#include "render/csg_spans.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// enter[s][l], exit[s][l]: the span of object `ob`'s shape s along lane l's ray.
template <class B>
inline void csg_packet_spans(const CsgView& csg, const CsgObjectView& ob, const RayPacket<B>& r,
                             float (*enter)[simd::kMaxLanes], float (*exit)[simd::kMaxLanes]) {
    for (std::uint32_t s = 0; s < ob.shape_count; ++s) {
        const ObjectXf& xf = csg.records[ob.first_shape + s].xf;
        const RayPacket<B> c = to_canonical<B, float>(r, xf);
        const SpanT<B> span = csg_shape_span<B>(ShapeKind(xf.kind), c.o, c.d, B(xf.param));
        span.enter.store_aligned(enter[s]);
        span.exit.store_aligned(exit[s]);
    }
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
            csg_packet_spans(csg, ob, r, enter, exit);
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
