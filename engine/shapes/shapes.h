#pragma once
// One definition of each canonical shape's math, used by the scalar baseline (V = double)
// and the SIMD kernels (V = xsimd batch). Each XxxMath has
//   hit_t(o, d, param, t_min, t_max): nearest t in (t_min, t_max) or +inf (miss; NaN-safe)
//   normal(p, param): outward, not necessarily unit, normal at a surface point
// where param is the torus minor radius and unused by the others.
#include <utility>

#include "shapes/shape_kind.h"
#include "shapes/cone_math.h"
#include "shapes/cube_math.h"
#include "shapes/cylinder_math.h"
#include "shapes/plane_math.h"
#include "shapes/sphere_math.h"
#include "shapes/torus_math.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct TorusMath {
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V minor, V t_min, V t_max) {
        return torus_hit_t(o, d, minor, t_min, t_max);
    }
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V minor) { return torus_normal(p, minor); }
};

/// Calls f(XxxMath{}) for the shape kind k. Meshes are not closed-form shapes: callers handle
/// ShapeKind::Mesh before (mesh/mesh_trace.h, kernels/mesh_kernel.h); here it falls through
/// to the plane so that every call still compiles to a total switch.
template <class F>
decltype(auto) visit_shape(ShapeKind k, F&& f) {
    switch (k) {
        case ShapeKind::Sphere: return f(SphereMath{});
        case ShapeKind::Cube: return f(CubeMath{});
        case ShapeKind::Cylinder: return f(CylinderMath{});
        case ShapeKind::Cone: return f(ConeMath{});
        case ShapeKind::Torus: return f(TorusMath{});
        case ShapeKind::Plane: break;
        case ShapeKind::Mesh: break;
    }
    return f(PlaneMath{});
}

STREAMRT_ISA_END
}  // namespace streamrt
