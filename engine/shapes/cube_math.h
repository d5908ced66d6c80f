#pragma once
// Canonical cube: [-1,1]^3.
#include "core/vec3.h"
#include "shapes/quadratic.h"
#include "shapes/shape_traits.h"
#include "shapes/solid_span.h"
#include "simd/isa_namespace.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

struct CubeMath {
    static constexpr ShapeKind kind = ShapeKind::Cube;
    static constexpr std::string_view name = "cube";
    static constexpr ShapeParam param = kNoShapeParam;
    using Compute = float;
    static constexpr CanonicalBounds bounds(double /*param*/) {
        return {CanonicalBounds::Form::Box, {-1, -1, -1}, {1, 1, 1}};
    }
    /// Slab test (Kay & Kajiya). A zero direction component gives +-inf slab distances; an
    /// origin exactly on that slab's face gives 0*inf = NaN, which the select-based max/min
    /// below ignore (the slab is then treated as not limiting, a grazing hit).
    template <class V>
    static V hit_t(const Vec3T<V>& o, const Vec3T<V>& d, V /*param*/, V t_min, V t_max) {
        using namespace simd;
        V t_near = -infinity_v<V>(), t_far = infinity_v<V>();
        const V o_arr[3] = {o.x, o.y, o.z}, d_arr[3] = {d.x, d.y, d.z};
        for (int axis = 0; axis < 3; ++axis) {
            const V inv = V(1) / d_arr[axis];
            const V ta = (V(-1) - o_arr[axis]) * inv;
            const V tb = (V(1) - o_arr[axis]) * inv;
            const V lo = select(ta < tb, ta, tb), hi = select(ta < tb, tb, ta);
            t_near = select(lo > t_near, lo, t_near);
            t_far = select(hi < t_far, hi, t_far);
        }
        // The NaN-tolerant max/min above would also swallow NaN inputs: reject those here.
        const V all = o.x + o.y + o.z + d.x + d.y + d.z;
        const auto spans = (t_near <= t_far) && (all - all == V(0));
        V best = keep_closest(t_max, t_near, spans, t_min);
        best = keep_closest(best, t_far, spans, t_min);  // from inside, t_near < t_min
        return miss_if_unchanged(best, t_max);
    }
    /// A convex closed solid: its inside along a line lies between hit_t's two ends (solid_span.h).
    static constexpr bool kConvexSolid = true;
    /// The face a point is on: the axis with the largest |coordinate| (x, then y, on ties).
    template <class V>
    struct Face {
        decltype(V() < V()) x, y, z;
    };
    template <class V>
    static Face<V> face(const Vec3T<V>& p) {
        using namespace simd;
        const V ax = abs(p.x), ay = abs(p.y), az = abs(p.z);
        const auto x_wins = (ax >= ay) && (ax >= az);
        const auto y_wins = !x_wins && (ay >= az);
        return {x_wins, y_wins, !x_wins && !y_wins};
    }
    template <class V>
    static Vec3T<V> normal(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const Face<V> f = face(p);
        return {select(f.x, sign_of(p.x), V(0)), select(f.y, sign_of(p.y), V(0)), select(f.z, sign_of(p.z), V(0))};
    }
    /// Each face shows the whole image, on the face the normal is: faces x = +-1 map (z, y),
    /// faces y = +-1 map (x, z), faces z = +-1 map (x, y), each coordinate a in [-1, 1] to
    /// (a + 1) / 2.
    template <class V>
    static UvT<V> uv(const Vec3T<V>& p, V /*param*/) {
        using namespace simd;
        const Face<V> f = face(p);
        return uv_square(select(f.x, p.z, p.x), select(f.y, p.z, p.y));
    }
    template <class V>
    static V uv_density(V /*param*/) { return V(0.5); }
};

STREAMRT_ISA_END
}  // namespace streamrt
