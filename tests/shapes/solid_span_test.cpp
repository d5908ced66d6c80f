// Each solid shape's span along a line (shapes/solid_span.h), against points worked out by
// hand from the canonical shapes' definitions (docs/scene-format.md), in float and double.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "shapes/shapes.h"

using namespace streamrt;

namespace {

template <class Math, class V>
SpanT<V> span_of(Vec3T<V> o, Vec3T<V> d) {
    return solid_span<Math>(o, d, V(0));
}

/// Equal within float rounding; an infinite end exactly (Approx cannot take infinities).
void check_end(double got, double want) {
    if (std::isinf(want)) CHECK(got == want);
    else CHECK(got == doctest::Approx(want).epsilon(1e-6));
}

template <class V>
void check_span(SpanT<V> s, double enter, double exit) {
    check_end(double(s.enter), enter);
    check_end(double(s.exit), exit);
}

template <class V>
bool empty(SpanT<V> s) {
    return !(s.enter <= s.exit);
}

}  // namespace

TEST_CASE_TEMPLATE("solid shapes: the convex ones span between their two crossings", V, float, double) {
    using P = Vec3T<V>;
    // Unit sphere from x = -5 along +x: in at x = -1, out at x = +1.
    check_span(span_of<SphereMath>(P{-5, 0, 0}, P{1, 0, 0}), 4.0, 6.0);
    // A direction of length 2 halves t; a line starting inside has a negative entry.
    check_span(span_of<SphereMath>(P{0, 0, 0}, P{0, 0, 2}), -0.5, 0.5);
    // Off centre at height 0.6: the chord is 2 * 0.8 long.
    check_span(span_of<SphereMath>(P{-5, 0.6f, 0}, P{1, 0, 0}), 4.2, 5.8);
    CHECK(empty(span_of<SphereMath>(P{-5, 1.5f, 0}, P{1, 0, 0})));
    // Cube [-1,1]^3: along y from y = -3 with speed 2; diagonally through two faces.
    check_span(span_of<CubeMath>(P{0, -3, 0}, P{0, 2, 0}), 1.0, 2.0);
    check_span(span_of<CubeMath>(P{-2, -2.5f, 0}, P{1, 1, 0}), 1.5, 3.0);
    CHECK(empty(span_of<CubeMath>(P{-5, 0, 1.5f}, P{1, 0, 0})));
    // Closed cylinder: along its axis through both caps, across its side, and past its end.
    check_span(span_of<CylinderMath>(P{0, -5, 0}, P{0, 1, 0}), 4.0, 6.0);
    check_span(span_of<CylinderMath>(P{-5, 0.5f, 0}, P{1, 0, 0}), 4.0, 6.0);
    check_span(span_of<CylinderMath>(P{-3, -2, 0}, P{1, 1, 0}), 2.0, 3.0);  // in by the side, out by the top cap
    CHECK(empty(span_of<CylinderMath>(P{-5, 1.5f, 0}, P{1, 0, 0})));
    // Closed cone (radius (1 - y) / 2): along its axis from base to apex; across at y = 0,
    // where the radius is 0.5.
    check_span(span_of<ConeMath>(P{0, -5, 0}, P{0, 1, 0}), 4.0, 6.0);
    check_span(span_of<ConeMath>(P{-5, 0, 0}, P{1, 0, 0}), 4.5, 5.5);
    CHECK(empty(span_of<ConeMath>(P{-5, 1.5f, 0}, P{1, 0, 0})));  // the other nappe is no part of it
}

TEST_CASE_TEMPLATE("solid shapes: the plane is the half-space below it", V, float, double) {
    using P = Vec3T<V>;
    const double inf = std::numeric_limits<double>::infinity();
    check_span(span_of<PlaneMath>(P{0, -2, 0}, P{0, 1, 0}), -inf, 2.0);   // rising: inside until y = 0
    check_span(span_of<PlaneMath>(P{0, 3, 0}, P{1, -2, 0}), 1.5, inf);    // falling: inside from y = 0
    check_span(span_of<PlaneMath>(P{0, -1, 0}, P{1, 0, 0}), -inf, inf);   // parallel, below: all of it
    CHECK(empty(span_of<PlaneMath>(P{0, 1, 0}, P{1, 0, 0})));            // parallel, above: none
}

TEST_CASE("solid shapes: which shapes a csg block may hold") {
    CHECK(shape_is_solid(ShapeKind::Sphere));
    CHECK(shape_is_solid(ShapeKind::Cube));
    CHECK(shape_is_solid(ShapeKind::Cylinder));
    CHECK(shape_is_solid(ShapeKind::Cone));
    CHECK(shape_is_solid(ShapeKind::Plane));
    CHECK(!shape_is_solid(ShapeKind::Disk));
    CHECK(shape_is_solid(ShapeKind::Torus));  // its tube's inside, in two spans
    CHECK(shape_csg_spans(ShapeKind::Torus) == 2);
    CHECK(shape_csg_spans(ShapeKind::Sphere) == 1);
    CHECK(!shape_is_solid(ShapeKind::Mesh));
}
