#pragma once
// Texture lookups, written once for both engines (V = double in the recursive baseline,
// float on the stream engine's scalar path, xsimd float batches in its SIMD shade kernel):
// the surface colour of a textured material at a hit (docs/scene-format.md, "Textures and
// UV mapping"). Bilinear filtering inside a mip level, linear between the two levels around
// the one the ray's footprint selects (trilinear). Texels are gathered lane by lane.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/vec3.h"
#include "mesh/mesh_view.h"
#include "render/shading.h"
#include "scene/texture.h"
#include "shapes/shapes.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

namespace texture_detail {
/// Wraps a texel coordinate x in [-1, n] into [0, n) (repeat).
inline std::int32_t wrap(std::int32_t x, std::int32_t n) { return x < 0 ? x + n : (x >= n ? x - n : x); }
}  // namespace texture_detail

/// Bilinear value of one level at (u, v), repeated outside [0, 1)^2. Texel (i, j) (column i,
/// row j from the top) has its centre at u = (i + 0.5) / width, v = 1 - (j + 0.5) / height:
/// v grows upwards in the image, as in OBJ files.
template <class T>
inline ColorT<T> texture_bilinear(const TextureLevelView& l, T u, T v) {
    using std::floor;
    if (!(u - u == T(0)) || !(v - v == T(0))) u = v = T(0);  // NaN or inf: any texel, no UB
    const T x = (u - floor(u)) * T(l.width) - T(0.5);
    const T y = (T(1) - (v - floor(v))) * T(l.height) - T(0.5);
    const T fx = floor(x), fy = floor(y);
    const T ax = x - fx, ay = y - fy;
    const std::int32_t x0 = texture_detail::wrap(std::int32_t(fx), l.width);
    const std::int32_t y0 = texture_detail::wrap(std::int32_t(fy), l.height);
    const std::int32_t x1 = texture_detail::wrap(x0 + 1, l.width), y1 = texture_detail::wrap(y0 + 1, l.height);
    const auto at = [&](std::int32_t i, std::int32_t j) {
        const float* p = l.rgb + (std::size_t(j) * std::size_t(l.width) + std::size_t(i)) * 3;
        return ColorT<T>{T(p[0]), T(p[1]), T(p[2])};
    };
    const ColorT<T> top = at(x0, y0) * (T(1) - ax) + at(x1, y0) * ax;
    const ColorT<T> bottom = at(x0, y1) * (T(1) - ax) + at(x1, y1) * ax;
    return top * (T(1) - ay) + bottom * ay;
}

/// The mip level for a footprint `texels` texels of the finest level wide: log2(texels),
/// 0 (the finest) for footprints up to one texel, at most the coarsest level.
template <class T>
inline T texture_lod(const TextureView& t, T texels) {
    using std::log2;
    const T lod = texels > T(1) ? log2(texels) : T(0);
    const T last = T(t.count - 1);
    return lod < last ? lod : last;  // NaN footprints give the coarsest level
}

/// Trilinear lookup of one point: bilinear in the two levels around texture_lod(texels),
/// mixed linearly.
template <class T>
inline ColorT<T> texture_sample(const TextureView& t, T u, T v, T texels) {
    using std::floor;
    const T lod = texture_lod(t, texels);
    const T l0 = floor(lod);
    const T f = lod - l0;
    const std::int32_t i = std::int32_t(l0);
    const ColorT<T> c0 = texture_bilinear(t.levels[i], u, v);
    if (!(f > T(0)) || i + 1 >= t.count) return c0;
    return c0 * (T(1) - f) + texture_bilinear(t.levels[i + 1], u, v) * f;
}

/// The lookup for every lane of V: one point for a scalar, lane by lane for a batch (the
/// texels of different lanes are anywhere in the image). The SIMD shade kernel calls the
/// scalar functions lane by lane instead (kernels/shade_kernel.h texture_colors), for the same
/// bits at every ISA level; batches serve tests and callers that need no such guarantee.
template <class V>
inline ColorT<V> texture_sample_lanes(const TextureView& t, const V& u, const V& v, const V& texels) {
    if constexpr (!simd::is_batch<V>) {
        return texture_sample(t, u, v, texels);
    } else {
        constexpr std::size_t W = V::size;
        alignas(64) float us[W], vs[W], ts[W], r[W], g[W], b[W];
        u.store_aligned(us);
        v.store_aligned(vs);
        texels.store_aligned(ts);
        for (std::size_t l = 0; l < W; ++l) {
            const ColorT<float> c = texture_sample(t, us[l], vs[l], ts[l]);
            r[l] = c.x;
            g[l] = c.y;
            b[l] = c.z;
        }
        return {V::load_aligned(r), V::load_aligned(g), V::load_aligned(b)};
    }
}

/// Canonical units per world unit of an object's placement, from Mi's rows (row-major 3x4):
/// the cube root of |det| of its linear part (exact for a uniform scale, the geometric mean
/// of the three scales otherwise).
template <class V, class Rows>
inline V canonical_per_world(const Rows& m) {
    using std::cbrt;
    using namespace simd;
    const V det = V(m[0]) * (V(m[5]) * V(m[10]) - V(m[6]) * V(m[9])) -
                  V(m[1]) * (V(m[4]) * V(m[10]) - V(m[6]) * V(m[8])) +
                  V(m[2]) * (V(m[4]) * V(m[9]) - V(m[5]) * V(m[8]));
    return cbrt(abs(det));
}

/// The colour of a textured material at a hit with texture coordinates uv: the footprint
/// (world units, render/shading.h footprint_width) becomes texels of the finest level as
/// footprint x canonical_per_world x density (the mapping's rate, UvT) x uvscale x the
/// image's larger side, which picks the mip level (texture_lod).
template <class V, class T>
inline ColorT<V> texture_color_at(const MaterialT<T>& m, const UvT<V>& uv, const V& density, const V& scale,
                                  const V& footprint) {
    const TextureLevelView& top = m.texture.levels[0];
    const T side = T(top.width > top.height ? top.width : top.height);
    const V k(m.uv_scale);
    return texture_sample_lanes(m.texture, uv.u * k, uv.v * k, footprint * scale * density * k * V(side));
}

/// The surface colour of a textured material on a canonical shape: uv from the canonical
/// hit point pc by the shape's mapping (shapes/*_math.h), then texture_color_at. `scale` is
/// the object's canonical_per_world (computed once per object where the caller can).
template <class V, class T>
inline ColorT<V> texture_color(const MaterialT<T>& m, ShapeKind kind, const Vec3T<V>& pc, const V& param,
                               const V& scale, const V& footprint) {
    UvT<V> uv;
    V density;
    visit_shape(kind, [&](auto shape) {
        uv = shape.template uv<V>(pc, param);
        density = shape.template uv_density<V>(param);
    });
    return texture_color_at(m, uv, density, scale, footprint);
}

/// A mesh's texture coordinates at barycentrics (bu, bv) of triangle tri: its corners' (OBJ
/// vt) weighted as the vertex normals are, (1 - bu - bv) c0 + bu c1 + bv c2.
template <class T>
inline UvT<T> mesh_uv(const MeshView& m, std::uint32_t tri, T bu, T bv) {
    const float* c = m.uv + 6 * std::size_t(tri);
    const T w = T(1) - bu - bv;
    return {T(c[0]) * w + T(c[2]) * bu + T(c[4]) * bv, T(c[1]) * w + T(c[3]) * bu + T(c[5]) * bv};
}

/// The surface colour of a textured material on a mesh (one hit; the SIMD kernel gathers
/// mesh_uv lane by lane and calls texture_color_at).
template <class T>
inline ColorT<T> mesh_texture_color(const MaterialT<T>& m, const MeshView& mesh, std::uint32_t tri, T bu, T bv,
                                    T scale, T footprint) {
    // The reader loads the coordinates of every mesh a textured object uses; (0, 0) otherwise.
    const UvT<T> uv = mesh.uv ? mesh_uv(mesh, tri, bu, bv) : UvT<T>{T(0), T(0)};
    return texture_color_at(m, uv, T(mesh.uv_density), scale, footprint);
}

STREAMRT_ISA_END
}  // namespace streamrt
