#pragma once
// The SIMD shade kernel: a run of rays that all hit one object (or, gathered, one material
// and shape kind) goes through the shading rules of render/shading.h (shade_hit) a packet at
// a time. Specialised at compile time on the features the scene uses. Included only by
// kernels/isa_*.cpp, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <limits>
#include <type_traits>

#include "kernels/compress.h"
#include "kernels/shade_job.h"
#include "mesh/terminator.h"
#include "render/shading.h"
#include "render/texture.h"
#include "shapes/shapes.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// Mi's twelve entries as batches: the same value in every lane (a run of one object,
/// broadcast where used, as a register held across the loop cost 6 % of the stage) or each
/// lane its own object's (a gathered run).
template <class B>
struct BroadcastRows {
    const float* m;
    B operator[](int k) const { return B(m[k]); }
};
template <class B>
struct LaneRows {
    B v[12];
    const B& operator[](int k) const { return v[k]; }
};

template <class B>
inline Vec3T<B> canonical_normal(ShapeKind kind, const Vec3T<B>& p, const B& param) {
    // One branch per packet (every lane hit the same object), never per ray. Meshes take
    // mesh_normals() below.
    return visit_shape(kind, [&](auto shape) { return shape.template normal<B>(p, param); });
}

/// Field `src` (one of the slice's arrays) of the run's rays i .. i + W, read through
/// ShadeJob::order lane by lane. Measured on the shade stage (scenes/whitted.cfg and
/// textured.cfg, 640x480 4 spp, -j1, medians of 9 alternated): the gather instructions were
/// no faster at AVX-512 (whitted 1.02x, textured 0.95x, glass bunny 1.04x the lane-by-lane
/// time) and slower at AVX2 (1.19x and 1.09x the copy into run order this replaced, where
/// lane by lane is 0.91x and 1.03x).
template <class A, class T>
inline xsimd::batch<T, A> run_field(const ShadeJob& job, std::size_t i, const T* src) {
    const std::int32_t* at = job.order + i;
    constexpr std::size_t W = xsimd::batch<T, A>::size;
    alignas(64) T lanes[W];
    for (std::size_t l = 0; l < W; ++l) lanes[l] = src[at[l]];
    return xsimd::batch<T, A>::load_aligned(lanes);
}

/// The record of lane l's object in the packet starting at ray i: the run's object, or
/// (kGathered) the lane's own, read through its id. Lanes past the run must not ask (their
/// ids belong to the next run, perhaps not a mesh).
template <bool kGathered>
inline const ObjectXf& lane_object(const ShadeJob& job, std::size_t i, std::size_t l) {
    if constexpr (kGathered) return job.objects[std::size_t(job.ids[job.order[i + l]])].xf;
    else return job.object->xf;
}

/// Canonical normals of a mesh's hits, gathered lane by lane from the hit triangles of each
/// lane's object (lane_object: one mesh per run, or each lane its own mesh and smooth flag):
/// the face normal, or the vertex normals interpolated at the barycentrics (mesh/mesh_trace.h's
/// mesh_normal, the same float expressions). Lanes past the run get +z.
template <class B, bool kGathered>
inline Vec3T<B> mesh_normals(const ShadeJob& job, std::size_t i) {
    constexpr std::size_t W = B::size;
    alignas(64) float nx[W], ny[W], nz[W];
    for (std::size_t l = 0; l < W; ++l) {
        nx[l] = ny[l] = 0.f;
        nz[l] = 1.f;
        if (i + l >= job.end) continue;
        const ObjectXf& ob = lane_object<kGathered>(job, i, l);
        const MeshView& m = *ob.mesh;
        const std::size_t ray = std::size_t(job.order[i + l]);
        const std::size_t k = std::size_t(job.prim[ray]);
        if (ob.param == 0.f) {  // flat
            const float *p = triangle_corner(m, k, 0), *p1 = triangle_corner(m, k, 1), *p2 = triangle_corner(m, k, 2);
            const float e1x = p1[0] - p[0], e1y = p1[1] - p[1], e1z = p1[2] - p[2];
            const float e2x = p2[0] - p[0], e2y = p2[1] - p[1], e2z = p2[2] - p[2];
            nx[l] = e1y * e2z - e1z * e2y;
            ny[l] = e1z * e2x - e1x * e2z;
            nz[l] = e1x * e2y - e1y * e2x;
        } else {
            const float u = job.bu[ray], v = job.bv[ray], w = 1.f - u - v;
            const float* n0 = m.vertex_normals + 3 * std::size_t(m.index[3 * k]);
            const float* n1 = m.vertex_normals + 3 * std::size_t(m.index[3 * k + 1]);
            const float* n2 = m.vertex_normals + 3 * std::size_t(m.index[3 * k + 2]);
            nx[l] = n0[0] * w + n1[0] * u + n2[0] * v;
            ny[l] = n0[1] * w + n1[1] * u + n2[1] * v;
            nz[l] = n0[2] * w + n1[2] * u + n2[2] * v;
        }
    }
    return {B::load_aligned(nx), B::load_aligned(ny), B::load_aligned(nz)};
}

/// The shift of each lane's shadow origin on a smooth mesh (mesh/terminator.h): the hit
/// triangles' corners, vertex normals and barycentrics gathered lane by lane from each lane's
/// object (lane_object; the floats smooth_corners reads), the formula in SIMD. Lanes past the
/// run, and (gathered) lanes of a flat mesh, get a flat triangle at (0, 0): no shift.
template <class B, bool kGathered, class Rows, class M>
inline Vec3T<B> terminator_shifts(const ShadeJob& job, std::size_t i, const Rows& rows, const M& outside) {
    constexpr std::size_t W = B::size;
    alignas(64) float corner[2][3][3][W], us[W], vs[W];  // [position / normal][corner][axis][lane]
    for (std::size_t l = 0; l < W; ++l) {
        const ObjectXf* ob = i + l < job.end ? &lane_object<kGathered>(job, i, l) : nullptr;
        if (!ob || ob->param == 0.f) {
            for (int j = 0; j < 3; ++j)
                for (int a = 0; a < 3; ++a) {
                    corner[0][j][a][l] = j == a + 1 ? 1.f : 0.f;
                    corner[1][j][a][l] = a == 2 ? 1.f : 0.f;
                }
            us[l] = vs[l] = 0.f;
            continue;
        }
        const MeshView& m = *ob->mesh;
        const std::size_t ray = std::size_t(job.order[i + l]);
        const std::size_t k = std::size_t(job.prim[ray]);
        for (int j = 0; j < 3; ++j) {
            const float* p = triangle_corner(m, k, j);
            const float* n = m.vertex_normals + 3 * std::size_t(m.index[3 * k + std::size_t(j)]);
            for (int a = 0; a < 3; ++a) {
                corner[0][j][a][l] = p[a];
                corner[1][j][a][l] = n[a];
            }
        }
        us[l] = job.bu[ray];
        vs[l] = job.bv[ray];
    }
    SmoothCorners<B> c;
    for (int j = 0; j < 3; ++j) {
        c.p[j] = {B::load_aligned(corner[0][j][0]), B::load_aligned(corner[0][j][1]), B::load_aligned(corner[0][j][2])};
        c.n[j] = {B::load_aligned(corner[1][j][0]), B::load_aligned(corner[1][j][1]), B::load_aligned(corner[1][j][2])};
    }
    return terminator_shift(rows, c, B::load_aligned(us), B::load_aligned(vs), outside);
}

/// The texture colour of each lane's hit (render/texture.h): the UV mapping, the mip level,
/// the weights and the texel offsets in SIMD, the texels gathered; the same operations as the
/// scalar shade path lane by lane, so the picture is the same bits at every ISA level (the
/// angles come from simd/stable_math.h, not xsimd's atan2, which rounds differently per
/// level). Meshes read their triangles' vt and their uv density lane by lane, from each lane's
/// object (lane_object). `scale`: the run's canonical_per_world, or (gathered, scale < 0)
/// each lane's, from its rows (a cube root per lane, in scalar float).
template <class B, bool kGathered, class Rows>
inline ColorT<B> texture_colors(const ShadeJob& job, std::size_t i, const MaterialT<float>& m, ShapeKind kind,
                                bool mesh, const Vec3T<B>& pc, const B& param, const Rows& rows, float scale,
                                const B& footprint) {
    constexpr std::size_t W = B::size;
    B sc(scale);
    if (scale < 0.f) {
        alignas(64) float rw[12][W], lanes[W];
        for (int k = 0; k < 12; ++k) B(rows[k]).store_aligned(rw[k]);
        for (std::size_t l = 0; l < W; ++l) {
            float mi[12];
            for (int k = 0; k < 12; ++k) mi[k] = rw[k][l];
            lanes[l] = canonical_per_world<float>(mi);
        }
        sc = B::load_aligned(lanes);
    }
    if (!mesh) return texture_color(m, kind, pc, param, sc, footprint);
    alignas(64) float us[W], vs[W], density[W];
    for (std::size_t l = 0; l < W; ++l) {
        // Lanes past the run have no triangle (their colour is never used); meshes without vt
        // read (0, 0), as the scalar path.
        const MeshView* mv = i + l < job.end ? lane_object<kGathered>(job, i, l).mesh : nullptr;
        const std::size_t ray = mv ? std::size_t(job.order[i + l]) : 0;
        const UvT<float> uv = mv && mv->uv ? mesh_uv(*mv, std::uint32_t(job.prim[ray]), job.bu[ray], job.bv[ray])
                                           : UvT<float>{0.f, 0.f};
        us[l] = uv.u;
        vs[l] = uv.v;
        density[l] = mv ? mv->uv_density : 1.f;
    }
    return texture_color_at(m, UvT<B>{B::load_aligned(us), B::load_aligned(vs)}, B::load_aligned(density), sc,
                            footprint);
}

/// Each lane's interpolated vertex colour (render/texture.h, mesh_vertex_color), gathered lane
/// by lane as texture_colors does; a lane past the run, or on a mesh read without colours,
/// keeps `fallback` (the object's colour).
template <class B, bool kGathered>
inline ColorT<B> vertex_colors(const ShadeJob& job, std::size_t i, const ColorT<B>& fallback) {
    constexpr std::size_t W = B::size;
    alignas(64) float r[W], g[W], b[W];
    fallback.x.store_aligned(r);
    fallback.y.store_aligned(g);
    fallback.z.store_aligned(b);
    for (std::size_t l = 0; l < W && i + l < job.end; ++l) {
        const MeshView* mv = lane_object<kGathered>(job, i, l).mesh;
        if (!mv || !mv->vertex_colors) continue;
        const std::size_t ray = std::size_t(job.order[i + l]);
        const ColorT<float> c = mesh_vertex_color(*mv, std::uint32_t(job.prim[ray]), job.bu[ray], job.bv[ray]);
        r[l] = c.x;
        g[l] = c.y;
        b[l] = c.z;
    }
    return {B::load_aligned(r), B::load_aligned(g), B::load_aligned(b)};
}

/// Appends the active lanes' rays to the next generation's stream, compacted.
template <class B, class M>
inline void append(const ShadeJob& job, std::size_t i, const M& active, const Vec3T<B>& o, const Vec3T<B>& d,
                   const ColorT<B>& w, const B& cone, RayKind kind) {
    using A = typename B::arch_type;
    const unsigned bits = lane_bits(active);
    if (bits == 0) return;
    const RayAppend& r = kind == RayKind::Refracted ? job.next_refracted
                         : kind == RayKind::Diffuse ? job.next_diffuse
                                                    : job.next;
    const std::size_t j = *r.count;
    compress_store(o.x, bits, r.ox + j);
    compress_store(o.y, bits, r.oy + j);
    compress_store(o.z, bits, r.oz + j);
    compress_store(d.x, bits, r.dx + j);
    compress_store(d.y, bits, r.dy + j);
    compress_store(d.z, bits, r.dz + j);
    compress_store(w.x, bits, r.wr + j);
    compress_store(w.y, bits, r.wg + j);
    compress_store(w.z, bits, r.wb + j);
    compress_store(cone, bits, r.cone + j);
    B(std::numeric_limits<float>::infinity()).store_unaligned(r.t_max + j);
    const std::size_t n =
        compress_store(run_field<A>(job, i, job.pixel), bits, r.pixel + j);
    std::memset(r.kind + j, int(kind), n);
    if (r.key) {  // area lights, degree 6: children inherit the key, or at degree 6 take their own
        using U = xsimd::batch<std::uint32_t, A>;
        U key = run_field<A>(job, i, job.key);
        if (job.rekey) key = child_key(key, std::uint32_t(kind));
        compress_store(xsimd::bitwise_cast<xsimd::batch<std::int32_t, A>>(key), bits,
                       reinterpret_cast<std::int32_t*>(r.key + j));
    }
    *r.count = j + n;
}

/// Where shade_hit's results go in the SIMD kernel: the packet's local colours into the
/// run's output arrays, shadow and child rays compacted into their streams.
template <class B>
struct SimdSink {
    static constexpr bool kTestsShadowsNow = false;
    using Mask = xsimd::batch_bool<float, typename B::arch_type>;
    const ShadeJob& job;
    std::size_t i;  ///< the packet's first ray in the run
    xsimd::batch<std::int32_t, typename B::arch_type> positions;  ///< i + lane: the lanes' run positions

    void local(const ColorT<B>& c) const {
        c.x.store_unaligned(job.lr + i);
        c.y.store_unaligned(job.lg + i);
        c.z.store_unaligned(job.lb + i);
    }
    void shadow(const Mask& send, const Vec3T<B>& from, const Vec3T<B>& to, const B& t_max, const ColorT<B>& c) const {
        const unsigned bits = lane_bits(send);
        if (bits == 0) return;
        const ShadowAppend& sa = job.shadows;
        const std::size_t j = *sa.count;
        compress_store(from.x, bits, sa.ox + j);
        compress_store(from.y, bits, sa.oy + j);
        compress_store(from.z, bits, sa.oz + j);
        compress_store(to.x, bits, sa.dx + j);
        compress_store(to.y, bits, sa.dy + j);
        compress_store(to.z, bits, sa.dz + j);
        compress_store(t_max, bits, sa.t_max + j);
        compress_store(c.x, bits, sa.cr + j);
        compress_store(c.y, bits, sa.cg + j);
        compress_store(c.z, bits, sa.cb + j);
        // Not the pixel: the hit's run position (ShadeJob::shadows).
        *sa.count = j + compress_store(positions, bits, sa.pixel + j);
    }
    void child(const Mask& send, const Vec3T<B>& from, const Vec3T<B>& dir, const ColorT<B>& weight, const ColorT<B>&,
               const B& cone, RayKind kind) const {
        append(job, i, send, from, dir, weight, cone, kind);
    }
    /// Area lights only: the packet's light-sampling keys.
    xsimd::batch<std::uint32_t, typename B::arch_type> light_key() const {
        return run_field<typename B::arch_type>(job, i, job.key);
    }
};

/// kGathered: the run shares a material and a shape kind, not an object; each lane's Mi, shape
/// parameter and colour are gathered from its object's records (the same values a run of that
/// object would broadcast, so the same arithmetic per lane).
template <class Arch, bool kLit, bool kShadows, bool kReflect, bool kRefract, bool kBounce, bool kGathered>
void shade_run(const ShadeJob& job) {
    using B = xsimd::batch<float, Arch>;
    using I = xsimd::batch<std::int32_t, Arch>;
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;  // see simd/lanes.h
    const ObjectXf& ob = kGathered ? job.objects[0].xf : job.object->xf;
    const ShapeKind kind = kGathered ? job.kind : ShapeKind(job.object->xf.kind);
    // Gather strides, in floats: a KernelObject is 16, a SurfaceRecord 4.
    static_assert(sizeof(KernelObject) == 16 * sizeof(float) && sizeof(SurfaceRecord) == 4 * sizeof(float));
    const float* object_floats = reinterpret_cast<const float*>(kGathered ? job.objects : job.object);
    const float* surface_floats = reinterpret_cast<const float*>(job.surfaces);
    const MaterialT<float>& m = *job.material;
    alignas(64) float lane_index[W];
    alignas(64) std::int32_t lane_number[W];
    for (std::size_t l = 0; l < W; ++l) lane_index[l] = float(l), lane_number[l] = std::int32_t(l);
    const I lane_numbers = I::load_aligned(lane_number);
    // Textures: the object's canonical units per world unit, once per run (gathered: per lane).
    const float run_scale = m.texture && !kGathered ? canonical_per_world<float>(ob.m) : -1.f;
    const B lanes = B::load_aligned(lane_index);
    // Shadow origins move off the flat triangles only on smooth meshes: the run's object, or
    // (gathered) the packet's smooth lanes.
    const bool smooth_mesh = kind == ShapeKind::Mesh && (kGathered || ob.param != 0.f);
    // A CSG shape's surface seen from the shape's outside (ObjectXf::flip) has its normal
    // turned round through Mn's rows negated, once per run: each product only changes sign,
    // so the bits are those of the normal negated (the scalar path's). Gathered runs never
    // hold CSG shapes (resolve_shade_mode).
    alignas(64) float flipped_rows[12];
    const float* normal_m = ob.m;
    if (!kGathered && ob.flip) {
        for (int k = 0; k < 12; ++k) flipped_rows[k] = -ob.m[k];
        normal_m = flipped_rows;
    }

    for (std::size_t i = job.begin; i < job.end; i += W) {
        // The last packet may be partial: its extra lanes read padding and are never stored
        // into a stream (their local colour lands in padding too).
        const auto active = lanes < B(float(job.end - i));
        // The packet's rays, gathered from the slice's arrays (ShadeJob::order).
        const auto field = [&](const float* src) { return run_field<Arch>(job, i, src); };
        const Vec3T<B> o{field(job.ox), field(job.oy), field(job.oz)};
        const Vec3T<B> d{field(job.dx), field(job.dy), field(job.dz)};
        const B t = field(job.t);
        const ColorT<B> w{field(job.wr), field(job.wg), field(job.wb)};

        // The object of each lane: broadcast from the run's record, or gathered per lane.
        std::conditional_t<kGathered, LaneRows<B>, BroadcastRows<B>> rows;
        B param;
        ColorT<B> color;
        if constexpr (kGathered) {
            const I ids = run_field<Arch>(job, i, job.ids);  // padding lanes read a hit's id
            const I at = ids * I(16), sat = ids * I(4);
            for (int k = 0; k < 12; ++k) rows.v[k] = gather_floats(object_floats + k, at);
            param = gather_floats(object_floats + 12, at);
            color = {gather_floats(surface_floats, sat), gather_floats(surface_floats + 1, sat),
                     gather_floats(surface_floats + 2, sat)};
        } else {
            rows.m = ob.m;
            param = B(ob.param);
            color = splat<B>(job.color);
        }
        // The canonical hit point gives the normal, brought back with Mn; the world point
        // is the ray's own.
        const Vec3T<B> pc = apply_point(rows, o) + apply_vector(rows, d) * t;
        const Vec3T<B> p = o + d * t;
        Vec3T<B> n_out{};
        if (kLit || m.checker || m.texture) {
            const Vec3T<B> nc =
                kind == ShapeKind::Mesh ? mesh_normals<B, kGathered>(job, i) : canonical_normal(kind, pc, param);
            if constexpr (kGathered) n_out = apply_normal(rows, nc);
            else n_out = apply_normal(BroadcastRows<B>{normal_m}, nc);
        }
        const ArrivingRay<B> arriving{o, d, t, field(job.cone), w, w};
        if (m.texture) {  // one branch per run: the texture replaces the object's colour
            const B footprint = footprint_width(arriving.cone, B(job.rules.spread), t, dot(d, n_out));
            color = texture_colors<B, kGathered>(job, i, m, kind, kind == ShapeKind::Mesh, pc, param, rows, run_scale,
                                                 footprint);
        } else if (m.vertex_colors && kind == ShapeKind::Mesh) {  // so do a mesh's vertex colours
            color = vertex_colors<B, kGathered>(job, i, color);
        }
        SimdSink<B> sink{job, i, lane_numbers + I(std::int32_t(i))};
        // A smooth mesh's shadow rays start from its curved patch, not the flat triangle (one
        // branch per run; gathered, the flat lanes keep their point and a packet with no
        // smooth lane skips the shift).
        const auto shadow_point = [&](const Vec3T<B>& at) {
            if (!smooth_mesh) return at;
            if constexpr (kGathered) {
                const auto smooth = (param != B(0.f)) & active;  // the lanes on a smooth mesh
                if (!xsimd::any(smooth)) return at;
                const Vec3T<B> shift = terminator_shifts<B, true>(job, i, rows, meets_outside(n_out, d));
                return select3(smooth, at + shift, at);
            } else {
                return at + terminator_shifts<B, false>(job, i, rows, meets_outside(n_out, d));
            }
        };
        shade_hit<kLit, kShadows, kReflect, kRefract, kBounce>(job.rules, m, job.lights, job.n_lights, arriving, p,
                                                               n_out, color, active, sink, shadow_point);
    }
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
