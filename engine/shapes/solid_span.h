#pragma once
// The inside of a solid shape along a line, for constructive solid geometry
// (docs/scene-format.md, "CSG"): each solid shape's math file gives inside_span, written once
// for float, double and batches like hit_t.
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "simd/isa_namespace.h"

namespace streamrt {

/// The most solids one CSG object combines. A line meets each solid (convex, or a half-space)
/// in at most one span, and combining lists of a and b spans gives at most a + b, so the span
/// lists of an object's nodes fit this bound: fixed arrays, nothing allocated per ray.
inline constexpr int kMaxCsgShapes = 64;

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

/// The stretch of the line o + t d (every t, negative too) inside a solid: t in [enter, exit].
/// A line that misses has enter > exit, or NaN (which every comparison takes as a miss).
/// The ends may be infinite (a half-space); an infinite end is no surface.
template <class V>
struct SpanT {
    V enter, exit;
};

/// A convex closed solid's span: the line crosses its surface once going in and once going out,
/// so the first crossing from each end of the line is the shape's own hit_t, run forwards and
/// backwards over every t. The span's ends are then the very points a plain object of the shape
/// is hit at. A miss gives enter = +inf, exit = -inf.
template <class Math, class V>
SpanT<V> convex_span(const Vec3T<V>& o, const Vec3T<V>& d, V param) {
    const V inf = infinity_v<V>();
    const V enter = Math::template hit_t<V>(o, d, param, -inf, inf);
    const V exit = -Math::template hit_t<V>(o, -d, param, -inf, inf);
    return {enter, exit};
}

/// A shape that is a solid for CSG with one span along a line: a convex one (kConvexSolid) or
/// one with its own inside_span (the plane's half-space). The disk is no solid.
template <class Math>
concept ConvexSolid = requires { requires Math::kConvexSolid; };
template <class Math>
concept Solid = ConvexSolid<Math> || requires(Vec3T<double> p, double v) { Math::inside_span(p, p, v); };
/// A solid a line may meet in several spans (the torus: two, shapes/torus_math.h torus_spans).
template <class Math>
concept MultiSpanSolid = requires { requires Math::kCsgSpans > 1; };

/// A shape whose two ends come from one computation (the sphere's one solve), with
/// convex_span's bits.
template <class Math, class V>
concept OwnSpan = requires(Vec3T<V> p, V v) { Math::template span<V>(p, p, v); };

/// The solid's span along the line o + t d, t in the units of d. A packet no lane of which
/// may meet a shape with a cheap pre-test (may_hit) spans nothing without the solve.
template <class Math, class V>
    requires Solid<Math>
SpanT<V> solid_span(const Vec3T<V>& o, const Vec3T<V>& d, V param) {
    if constexpr (simd::is_batch<V> && requires { Math::may_hit(o, d); }) {
        if (!simd::any(Math::may_hit(o, d))) return {infinity_v<V>(), -infinity_v<V>()};
    }
    if constexpr (OwnSpan<Math, V>) return Math::template span<V>(o, d, param);
    else if constexpr (ConvexSolid<Math>) return convex_span<Math>(o, d, param);
    else return Math::inside_span(o, d, param);
}

STREAMRT_ISA_END
}  // namespace streamrt
