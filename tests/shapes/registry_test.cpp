// The shape registry (shapes/shapes.h): what it checks at compile time, and that everything
// generated from it (keywords, keys, bounds, kernel tables, the switch) covers every shape.
//
// A shape missing a member does not compile. Shown once by hand (docs/testing.md, faults
// table) by registering a copy of DiskMath without normal():
//   using CanonicalShapes = ShapeList<..., PlaneMath, DiskWithoutNormal>;
// GCC 12: "shapes/shapes.h: error: static assertion failed: a canonical shape declares
// template <class V> Vec3T<V> normal(p, param)". The static_asserts below keep that proof in
// the suite without a failing build: the concept rejects such types.
#include <doctest/doctest.h>

#include <set>
#include <string>

#include "kernels/kernel_table.h"
#include "shapes/shapes.h"

using namespace streamrt;

namespace {

/// DiskMath without its normal: not a CanonicalShape.
struct DiskWithoutNormal {
    static constexpr ShapeKind kind = ShapeKind::Disk;
    static constexpr std::string_view name = "disk";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    static constexpr CanonicalBounds bounds(double p) { return DiskMath::bounds(p); }
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V p, V t_min, V t_max) {
        return DiskMath::hit_t(o, d, p, t_min, t_max);
    }
};
/// ... without bounds.
struct DiskWithoutBounds {
    static constexpr ShapeKind kind = ShapeKind::Disk;
    static constexpr std::string_view name = "disk";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V p, V t_min, V t_max) {
        return DiskMath::hit_t(o, d, p, t_min, t_max);
    }
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V q) { return DiskMath::normal(p, q); }
};
struct DiskWithIntCompute : DiskMath {
    using Compute = int;  // the kernels' lanes are float or double
};

static_assert(CanonicalShape<DiskMath>);
static_assert(!CanonicalShape<DiskWithoutNormal>, "a shape without normal() must not register");
static_assert(!CanonicalShape<DiskWithoutBounds>, "a shape without bounds() must not register");
static_assert(!CanonicalShape<DiskWithIntCompute>);
static_assert(!CanonicalShape<int>);

}  // namespace

TEST_CASE("registry: one canonical shape per kind but Mesh, in kind order, distinct names") {
    std::set<std::string> names;
    int i = 0;
    CanonicalShapes::for_each([&](auto s) {
        CHECK(int(s.kind) == i++);
        names.insert(std::string(s.name));
        CHECK(canonical_shape_named(s.name) == s.kind);
        CHECK(std::string(shape_kind_name(s.kind)) == std::string(s.name));
        // visit_shape reaches this shape for its kind.
        CHECK(visit_shape(s.kind, [](auto v) { return int(v.kind); }) == int(s.kind));
    });
    CHECK(i == kShapeKindCount - 1);
    CHECK(names.size() == std::size_t(i));
    CHECK(std::string(shape_kind_name(ShapeKind::Mesh)) == "mesh");
    CHECK_FALSE(canonical_shape_named("mesh").has_value());
    CHECK_FALSE(canonical_shape_named("disc").has_value());
}

TEST_CASE("registry: every kind has all four kernels at every ISA") {
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const KernelTable& kt = kernel_table(isa);
        for (int k = 0; k < kShapeKindCount; ++k) {
            CAPTURE(k);
            CHECK(bool(kt.closest[k]));
            CHECK(bool(kt.any[k]));
            CHECK(bool(kt.closest_culled[k]));
            CHECK(bool(kt.any_culled[k]));
        }
    }
}

TEST_CASE("registry: canonical bounds contain points of each shape's surface") {
    // Points on each surface (hit by rays from outside towards the centre, every direction of
    // a small set) lie within the declared bounds.
    CanonicalShapes::for_each([&](auto s) {
        using S = decltype(s);
        const double param = S::param.present() ? S::param.default_value : 0.0;
        const CanonicalBounds b = S::bounds(param);
        CAPTURE(std::string(S::name));
        int hits = 0;
        for (int i = 0; i < 200; ++i) {
            const double a = 0.1 + i * 0.61803398875, c = 0.3 + i * 0.41421356237;
            const Vec3d dir{std::cos(a) * std::sin(c), std::cos(c), std::sin(a) * std::sin(c)};
            const Vec3d o{-10 * dir.x + 0.3 * std::sin(3.0 * i), -10 * dir.y + 0.2 * std::cos(5.0 * i), -10 * dir.z};
            const double t = S::template hit_t<double>(o, dir, param, 0.0, 1e30);
            if (!(t < 1e30)) continue;
            ++hits;
            const Vec3d p = o + dir * t;
            const double at[3] = {p.x, p.y, p.z};
            for (int k = 0; k < 3; ++k) {
                CHECK(at[k] >= b.lo[k] - 1e-9);
                CHECK(at[k] <= b.hi[k] + 1e-9);
            }
        }
        CHECK(hits > 20);
    });
}
