#pragma once
// The registry of canonical shapes. Each shape declares itself once, in its math file
// (kind, scene-format name, parameter key, canonical bounds, kernel precision, hit_t and
// normal: shapes/shape_traits.h); CanonicalShapes below lists them, and everything the
// engines do per kind is generated from that list at compile time: visit_shape (the
// switches of the baseline, the scalar and SIMD shade paths and the hierarchy's leaves), the
// kernels' per-kind tables (kernels/intersect_kernel.h), the reader's keywords and keys
// (scene/parser.cpp), the bounds (scene/scene_bvh.cpp) and the benchmarks. Adding a shape:
// its math file, its ShapeKind, one line here (docs/architecture.md, "Adding a shape").
#include <cstddef>
#include <optional>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "shapes/cone_math.h"
#include "shapes/cube_math.h"
#include "shapes/cylinder_math.h"
#include "shapes/disk_math.h"
#include "shapes/plane_math.h"
#include "shapes/shape_kind.h"
#include "shapes/shape_traits.h"
#include "shapes/sphere_math.h"
#include "shapes/torus_math.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

namespace shape_detail {
/// Names the first member a would-be shape lacks (a plainer message than the concept's).
template <class S>
constexpr bool declares_every_member() {
    static_assert(requires { S::kind; }, "a canonical shape declares static constexpr ShapeKind kind");
    static_assert(requires { S::name; }, "a canonical shape declares its scene-format std::string_view name");
    static_assert(requires { S::param; }, "a canonical shape declares ShapeParam param (or kNoShapeParam)");
    static_assert(requires(double p) { S::bounds(p); }, "a canonical shape declares CanonicalBounds bounds(param)");
    static_assert(requires { typename S::Compute; }, "a canonical shape declares using Compute = float or double");
    static_assert(requires(const Vec3T<double>& v, double x) { S::template hit_t<double>(v, v, x, x, x); },
                  "a canonical shape declares template <class V> V hit_t(o, d, param, t_min, t_max)");
    static_assert(requires(const Vec3T<double>& v, double x) { S::template normal<double>(v, x); },
                  "a canonical shape declares template <class V> Vec3T<V> normal(p, param)");
    static_assert(requires(const Vec3T<double>& v, double x) { S::template uv<double>(v, x); },
                  "a canonical shape declares template <class V> UvT<V> uv(p, param) (its texture mapping)");
    static_assert(requires(double x) { S::template uv_density<double>(x); },
                  "a canonical shape declares template <class V> V uv_density(param)");
    static_assert(CanonicalShape<S>, "a canonical shape's members have the types of shapes/shape_traits.h");
    return true;
}
}  // namespace shape_detail

/// A list of canonical shapes; each must provide every member (CanonicalShape), or the list
/// does not compile: the first missing member is named.
template <class... S>
struct ShapeList {
    static_assert((shape_detail::declares_every_member<S>() && ...));
    static constexpr std::size_t size = sizeof...(S);
    template <std::size_t I>
    using at = std::tuple_element_t<I, std::tuple<S...>>;
    /// Calls f(S{}) for every shape, in order.
    template <class F>
    static constexpr void for_each(F&& f) { (f(S{}), ...); }
    /// Shape i has kind i: the list and ShapeKind are in the same order.
    static constexpr bool in_kind_order() {
        std::size_t i = 0;
        return ((std::size_t(S::kind) == i++) && ...);
    }
    static constexpr bool names_distinct() {
        const std::string_view names[] = {S::name...};
        for (std::size_t a = 0; a < size; ++a)
            for (std::size_t b = a + 1; b < size; ++b)
                if (names[a] == names[b]) return false;
        return true;
    }
};

/// THE registration list: every canonical shape, in ShapeKind order.
using CanonicalShapes = ShapeList<SphereMath, CubeMath, CylinderMath, ConeMath, TorusMath, PlaneMath, DiskMath>;

inline constexpr std::size_t kCanonicalShapeCount = CanonicalShapes::size;
static_assert(kCanonicalShapeCount == std::size_t(kShapeKindCount) - 1,
              "every ShapeKind but Mesh must be registered in CanonicalShapes (shapes/shapes.h)");
static_assert(CanonicalShapes::in_kind_order(), "CanonicalShapes must list the shapes in ShapeKind order");
static_assert(std::size_t(ShapeKind::Mesh) == kCanonicalShapeCount, "Mesh is the last ShapeKind");
static_assert(CanonicalShapes::names_distinct(), "two canonical shapes share a scene-format name");

namespace shape_detail {
template <std::size_t I, class F>
inline decltype(auto) call_with(F& f) {  // a template on F, so an unused case is never instantiated
    return f(typename CanonicalShapes::template at<I>{});
}
}  // namespace shape_detail

/// Calls f(XxxMath{}) for the canonical shape of kind k: a switch generated from
/// CanonicalShapes (a jump table, the lambda inlined in each case, as a hand-written switch).
/// Meshes are not closed-form: callers handle ShapeKind::Mesh before (mesh/mesh_trace.h,
/// kernels/mesh_kernel.h); Mesh or a value outside the enum here is a bug and traps, rather
/// than falling through to some shape.
template <class F>
inline decltype(auto) visit_shape(ShapeKind k, F&& f) {
    static_assert(kCanonicalShapeCount <= 16, "visit_shape: add cases below");
    switch (std::size_t(k)) {
#define STREAMRT_SHAPE_CASE(i)                                                   \
    case i:                                                                      \
        if constexpr ((i) < kCanonicalShapeCount) return shape_detail::call_with<(i)>(f); \
        else break;
        STREAMRT_SHAPE_CASE(0)
        STREAMRT_SHAPE_CASE(1)
        STREAMRT_SHAPE_CASE(2)
        STREAMRT_SHAPE_CASE(3)
        STREAMRT_SHAPE_CASE(4)
        STREAMRT_SHAPE_CASE(5)
        STREAMRT_SHAPE_CASE(6)
        STREAMRT_SHAPE_CASE(7)
        STREAMRT_SHAPE_CASE(8)
        STREAMRT_SHAPE_CASE(9)
        STREAMRT_SHAPE_CASE(10)
        STREAMRT_SHAPE_CASE(11)
        STREAMRT_SHAPE_CASE(12)
        STREAMRT_SHAPE_CASE(13)
        STREAMRT_SHAPE_CASE(14)
        STREAMRT_SHAPE_CASE(15)
#undef STREAMRT_SHAPE_CASE
        default: break;
    }
    __builtin_trap();
}

/// The keyword of each kind in the scene format (names are string literals, so .data() ends
/// with a NUL).
constexpr const char* shape_kind_name(ShapeKind k) {
    if (k == ShapeKind::Mesh) return "mesh";
    const char* name = "?";
    CanonicalShapes::for_each([&](auto s) {
        if (s.kind == k) name = s.name.data();
    });
    return name;
}

/// The canonical shape a statement keyword names (not "mesh").
constexpr std::optional<ShapeKind> canonical_shape_named(std::string_view word) {
    std::optional<ShapeKind> kind;
    CanonicalShapes::for_each([&](auto s) {
        if (s.name == word) kind = s.kind;
    });
    return kind;
}

/// A canonical kind's parameter key and default (kNoShapeParam for Mesh).
constexpr ShapeParam shape_param(ShapeKind k) {
    ShapeParam p = kNoShapeParam;
    CanonicalShapes::for_each([&](auto s) {
        if (s.kind == k) p = s.param;
    });
    return p;
}

/// A canonical kind's bounds for its parameter (meshes: scene/scene_bvh.cpp).
constexpr CanonicalBounds canonical_bounds(ShapeKind k, double param) {
    CanonicalBounds b{CanonicalBounds::Form::Unbounded, {0, 0, 0}, {0, 0, 0}};
    CanonicalShapes::for_each([&](auto s) {
        if (s.kind == k) b = s.bounds(param);
    });
    return b;
}

/// Whether the canonical kind is a solid a csg block may hold (shapes/solid_span.h).
constexpr bool shape_is_solid(ShapeKind k) {
    bool solid = false;
    CanonicalShapes::for_each([&](auto s) {
        if (s.kind == k) solid = Solid<decltype(s)> || MultiSpanSolid<decltype(s)>;
    });
    return solid;
}

/// The spans a line may meet a canonical solid in (its CSG slots): 1, or its kCsgSpans.
constexpr int shape_csg_spans(ShapeKind k) {
    int n = 1;
    CanonicalShapes::for_each([&](auto s) {
        if constexpr (MultiSpanSolid<decltype(s)>) {
            if (s.kind == k) n = decltype(s)::kCsgSpans;
        }
    });
    return n;
}

/// Whether the kernels solve this kind in double lanes (half as many per register).
constexpr bool shape_computes_in_double(ShapeKind k) {
    bool dbl = false;
    CanonicalShapes::for_each([&](auto s) {
        if (s.kind == k) dbl = std::is_same_v<typename decltype(s)::Compute, double>;
    });
    return dbl;
}

STREAMRT_ISA_END
}  // namespace streamrt
