#pragma once
// Canonical disk: x^2 + z^2 <= 1 in the plane y = 0, normal +y (one-sided geometry like the
// plane; the engines turn normals to face the viewer).
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "shapes/shape_traits.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct DiskMath {
    static constexpr ShapeKind kind = ShapeKind::Disk;
    static constexpr std::string_view name = "disk";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    /// Flat: [-1,1] x [0,0] x [-1,1]. The hierarchy pads every box outwards by a relative and
    /// an absolute margin and a float ulp (accel::conservative_box; the flat kernels'
    /// ObjectBounds likewise), so the zero thickness becomes a non-empty float slab that
    /// contains the plane the shape math intersects (tests/shapes/disk_test.cpp).
    static constexpr CanonicalBounds bounds(double /*param*/) {
        return {CanonicalBounds::Form::Box, {-1, 0, -1}, {1, 0, 1}};
    }
    /// The plane's crossing, kept inside the unit circle (the rim counts). A ray parallel to
    /// the disk gives t = +-inf or NaN, and NaN or inf in x or z fail the circle test: misses.
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/, V t_min, V t_max) {
        return miss_if_unchanged(keep_cap(t_max, o, d, V(0), t_min), t_max);
    }
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& /*p*/, V /*param*/) { return {V(0), V(1), V(0)}; }
    /// Planar: the square around the disk, ((x + 1) / 2, (z + 1) / 2).
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*param*/) { return uv_square(p.x, p.z); }
    template <class V>
    static V uv_density(V /*param*/) { return V(0.5); }
};

STREAMRT_ISA_END
}  // namespace streamrt
