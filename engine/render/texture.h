#pragma once
// Texture lookups, written once for both engines (V = double in the recursive baseline,
// float on the stream engine's scalar path, xsimd float batches in its SIMD shade kernel):
// the surface colour of a textured material at a hit (docs/scene-format.md, "Textures and
// UV mapping"). Bilinear filtering inside a mip level, linear between the two levels around
// the one the ray's footprint selects (trilinear). Batches compute the coordinates, the mip
// level and the weights in SIMD and gather the texels; the same operations as the scalar
// path, so the same bits at every ISA level.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/vec3.h"
#include "mesh/mesh_view.h"
#include "render/shading.h"
#include "scene/texture.h"
#include "shapes/shapes.h"
#include "simd/gather.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"
#include "simd/stable_math.h"

namespace streamrt {
STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

namespace texture_detail {
/// Wraps a texel coordinate x in [-1, n] into [0, n) (repeat).
inline std::int32_t wrap(std::int32_t x, std::int32_t n) { return x < 0 ? x + n : (x >= n ? x - n : x); }
/// The same for a batch of whole numbers in [-1, n] held as floats (exact: n < 2^24).
template <class T>
inline T wrap_lanes(const T& x, std::int32_t n) {
    const T w = T(float(n));
    return xsimd::select(x < T(0), x + w, xsimd::select(x >= w, x - w, x));
}

template <class T>
inline ColorT<T> texel(const TextureLevelView& l, std::int32_t i, std::int32_t j) {
    const float* p = l.rgb + (std::size_t(j) * std::size_t(l.width) + std::size_t(i)) * 3;
    return {T(p[0]), T(p[1]), T(p[2])};
}
/// The texels (i, j) of every lane (whole numbers held as floats), gathered: the texel's
/// number j width + i is below 2^24 (scene/texture.h kMaxTextureTexels), so exact in float.
template <class T>
inline ColorT<T> texel_lanes(const TextureLevelView& l, const T& i, const T& j) {
    using I = xsimd::batch<std::int32_t, typename T::arch_type>;
    const I n = xsimd::to_int(j * T(float(l.width)) + i);
    const I at = n + n + n;
    return {simd::gather(l.rgb, at), simd::gather(l.rgb + 1, at), simd::gather(l.rgb + 2, at)};
}

template <class T, class M>
inline ColorT<T> select_color(const M& m, const ColorT<T>& a, const ColorT<T>& b) {
    return {simd::select(m, a.x, b.x), simd::select(m, a.y, b.y), simd::select(m, a.z, b.z)};
}
}  // namespace texture_detail

/// Bilinear value of one level at (u, v), repeated outside [0, 1)^2. Texel (i, j) (column i,
/// row j from the top) has its centre at u = (i + 0.5) / width, v = 1 - (j + 0.5) / height:
/// v grows upwards in the image, as in OBJ files. Written once for scalars and batches (the
/// same operations lane by lane: the same bits).
template <class T>
inline ColorT<T> texture_bilinear(const TextureLevelView& l, T u, T v) {
    using std::floor;
    using namespace texture_detail;
    const auto finite = (u - u == T(0)) && (v - v == T(0));  // NaN or inf: any texel, no UB
    u = simd::select(finite, u, T(0));
    v = simd::select(finite, v, T(0));
    const T x = (u - floor(u)) * T(l.width) - T(0.5);
    const T y = (T(1) - (v - floor(v))) * T(l.height) - T(0.5);
    const T fx = floor(x), fy = floor(y);
    const T ax = x - fx, ay = y - fy;
    ColorT<T> c00, c10, c01, c11;
    if constexpr (!simd::is_batch<T>) {
        const std::int32_t x0 = wrap(std::int32_t(fx), l.width), y0 = wrap(std::int32_t(fy), l.height);
        const std::int32_t x1 = wrap(x0 + 1, l.width), y1 = wrap(y0 + 1, l.height);
        c00 = texel<T>(l, x0, y0), c10 = texel<T>(l, x1, y0), c01 = texel<T>(l, x0, y1), c11 = texel<T>(l, x1, y1);
    } else {
        const T x0 = wrap_lanes(fx, l.width), y0 = wrap_lanes(fy, l.height);
        const T x1 = wrap_lanes(x0 + T(1), l.width), y1 = wrap_lanes(y0 + T(1), l.height);
        c00 = texel_lanes<T>(l, x0, y0), c10 = texel_lanes<T>(l, x1, y0);
        c01 = texel_lanes<T>(l, x0, y1), c11 = texel_lanes<T>(l, x1, y1);
    }
    const ColorT<T> top = c00 * (T(1) - ax) + c10 * ax;
    const ColorT<T> bottom = c01 * (T(1) - ax) + c11 * ax;
    return top * (T(1) - ay) + bottom * ay;
}

/// The mip level for a footprint `texels` texels of the finest level wide: log2(texels)
/// (simd/stable_math.h, within 1.1e-9), 0 (the finest) for footprints up to one texel or
/// NaN, at most the coarsest level.
template <class T>
inline T texture_lod(const TextureView& t, T texels) {
    using namespace simd;
    const T last = T(t.count - 1);
    const T x = select(texels > T(1), min(texels, T(1e30)), T(1));  // finite and normal
    return min(stable_log2(x), last);
}

/// Trilinear lookup: bilinear in the two levels around texture_lod(texels), mixed linearly.
/// A batch's lanes may need different levels: each level some lane needs is read for the
/// whole batch (one or two, rarely three, for the lanes of one packet) and kept where needed.
template <class T>
inline ColorT<T> texture_sample(const TextureView& t, T u, T v, T texels) {
    using std::floor;
    using namespace texture_detail;
    const T lod = texture_lod(t, texels);
    const T l0 = floor(lod);
    const T f = lod - l0;
    if constexpr (!simd::is_batch<T>) {
        const std::int32_t i = std::int32_t(l0);
        const ColorT<T> c0 = texture_bilinear(t.levels[i], u, v);
        if (!(f > T(0)) || i + 1 >= t.count) return c0;
        return c0 * (T(1) - f) + texture_bilinear(t.levels[i + 1], u, v) * f;
    } else {
        const auto mix = f > T(0) && l0 + T(1) < T(t.count);
        alignas(64) float first[T::size], last[T::size];
        l0.store_aligned(first);
        (l0 + simd::select(mix, T(1), T(0))).store_aligned(last);
        float lo = first[0], hi = last[0];
        for (std::size_t k = 1; k < T::size; ++k) lo = first[k] < lo ? first[k] : lo, hi = last[k] > hi ? last[k] : hi;
        ColorT<T> c0{T(0), T(0), T(0)}, c1{T(0), T(0), T(0)};
        for (std::int32_t i = std::int32_t(lo); i <= std::int32_t(hi); ++i) {
            const ColorT<T> c = texture_bilinear(t.levels[i], u, v);
            c0 = select_color(l0 == T(float(i)), c, c0);
            c1 = select_color(l0 + T(1) == T(float(i)), c, c1);
        }
        return select_color(mix, c0 * (T(1) - f) + c1 * f, c0);
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
    return texture_sample(m.texture, uv.u * k, uv.v * k, footprint * scale * density * k * V(side));
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

/// A mesh's colour at barycentrics (bu, bv) of triangle tri (vertex_colors=true): its
/// vertices' colours (MeshView::vertex_colors, linear) weighted as the vertex normals are,
/// (1 - bu - bv) c0 + bu c1 + bv c2. Interpolated in linear light, like every other colour.
template <class T>
inline ColorT<T> mesh_vertex_color(const MeshView& m, std::uint32_t tri, T bu, T bv) {
    const std::uint32_t* v = m.index + 3 * std::size_t(tri);
    const float *c0 = m.vertex_colors + 3 * std::size_t(v[0]), *c1 = m.vertex_colors + 3 * std::size_t(v[1]),
                *c2 = m.vertex_colors + 3 * std::size_t(v[2]);
    const T w = T(1) - bu - bv;
    return {T(c0[0]) * w + T(c1[0]) * bu + T(c2[0]) * bv, T(c0[1]) * w + T(c1[1]) * bu + T(c2[1]) * bv,
            T(c0[2]) * w + T(c1[2]) * bu + T(c2[2]) * bv};
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
