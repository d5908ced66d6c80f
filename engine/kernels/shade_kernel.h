#pragma once
// The SIMD shade kernel: local terms by degree, shadow rays, reflected and refracted rays
// for a run of rays that all hit one object. Specialised at compile time on the features
// the scene uses. Included only by kernels/isa_*.cpp, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <limits>
#include <type_traits>

#include "kernels/compress.h"
#include "kernels/shade_job.h"
#include "render/shading.h"
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

template <class B, class M>
inline Vec3T<B> apply_point(const M& m, const Vec3T<B>& p) {
    return {simd::mul_add(m[0], p.x, simd::mul_add(m[1], p.y, simd::mul_add(m[2], p.z, m[3]))),
            simd::mul_add(m[4], p.x, simd::mul_add(m[5], p.y, simd::mul_add(m[6], p.z, m[7]))),
            simd::mul_add(m[8], p.x, simd::mul_add(m[9], p.y, simd::mul_add(m[10], p.z, m[11])))};
}
template <class B, class M>
inline Vec3T<B> apply_vector(const M& m, const Vec3T<B>& v) {
    return {simd::mul_add(m[0], v.x, simd::mul_add(m[1], v.y, m[2] * v.z)),
            simd::mul_add(m[4], v.x, simd::mul_add(m[5], v.y, m[6] * v.z)),
            simd::mul_add(m[8], v.x, simd::mul_add(m[9], v.y, m[10] * v.z))};
}
/// Mn n with Mn = (Mi's linear part) transposed, read from Mi's row-major 3x4 rows.
template <class B, class M>
inline Vec3T<B> apply_normal(const M& mi, const Vec3T<B>& n) {
    return normalize(Vec3T<B>{simd::mul_add(mi[0], n.x, simd::mul_add(mi[4], n.y, mi[8] * n.z)),
                              simd::mul_add(mi[1], n.x, simd::mul_add(mi[5], n.y, mi[9] * n.z)),
                              simd::mul_add(mi[2], n.x, simd::mul_add(mi[6], n.y, mi[10] * n.z))});
}

template <class B>
inline Vec3T<B> canonical_normal(ShapeKind kind, const Vec3T<B>& p, const B& param) {
    // One branch per packet (every lane hit the same object), never per ray.
    switch (kind) {
        case ShapeKind::Sphere: return SphereMath::normal<B>(p, param);
        case ShapeKind::Cube: return CubeMath::normal<B>(p, param);
        case ShapeKind::Cylinder: return CylinderMath::normal<B>(p, param);
        case ShapeKind::Cone: return ConeMath::normal<B>(p, param);
        case ShapeKind::Torus: return TorusMath::normal<B>(p, param);
        case ShapeKind::Plane: break;
        case ShapeKind::Mesh: break;  // mesh_normals() below
    }
    return PlaneMath::normal<B>(p, param);
}

/// Canonical normals of a mesh's hits, gathered lane by lane from the hit triangles: the face
/// normal, or the vertex normals interpolated at the barycentrics (mesh/mesh_trace.h's
/// mesh_normal, the same float expressions). Lanes past the run get +z.
template <class B>
inline Vec3T<B> mesh_normals(const ShadeJob& job, std::size_t i) {
    constexpr std::size_t W = B::size;
    const MeshView& m = *job.object->xf.mesh;
    const bool smooth = job.object->xf.param != 0.f;
    alignas(64) float nx[W], ny[W], nz[W];
    for (std::size_t l = 0; l < W; ++l) {
        nx[l] = ny[l] = 0.f;
        nz[l] = 1.f;
        if (i + l >= job.end) continue;
        const std::size_t k = std::size_t(job.prim[i + l]);
        if (!smooth) {
            const float* p = m.tri + 9 * k;
            const float e1x = p[3] - p[0], e1y = p[4] - p[1], e1z = p[5] - p[2];
            const float e2x = p[6] - p[0], e2y = p[7] - p[1], e2z = p[8] - p[2];
            nx[l] = e1y * e2z - e1z * e2y;
            ny[l] = e1z * e2x - e1x * e2z;
            nz[l] = e1x * e2y - e1y * e2x;
        } else {
            const float u = job.bu[i + l], v = job.bv[i + l], w = 1.f - u - v;
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

/// Appends the active lanes' rays to the next generation's stream, compacted.
template <class B, class M>
inline void append(const ShadeJob& job, std::size_t i, const M& active, const Vec3T<B>& o, const Vec3T<B>& d,
                   const ColorT<B>& w, const B& cone, RayKind kind) {
    using A = typename B::arch_type;
    const unsigned bits = lane_bits(active);
    if (bits == 0) return;
    const RayAppend& r = job.next;
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
        compress_store(xsimd::batch<std::int32_t, A>::load_unaligned(job.pixel + i), bits, r.pixel + j);
    std::memset(r.kind + j, int(kind), n);
    *r.count = j + n;
}

/// kGathered: the run shares a material and a shape kind, not an object; each lane's Mi, shape
/// parameter and colour are gathered from its object's records (the same values a run of that
/// object would broadcast, so the same arithmetic per lane).
template <class Arch, bool kLit, bool kShadows, bool kReflect, bool kRefract, bool kGathered>
void shade_run(const ShadeJob& job) {
    using B = xsimd::batch<float, Arch>;
    using I = xsimd::batch<std::int32_t, Arch>;
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;  // see simd/lanes.h
    const ObjectXf& ob = kGathered ? job.objects[0].xf : job.object->xf;
    const ShapeKind kind = kGathered ? job.kind : ShapeKind(job.object->kind);
    // Gather strides, in floats: a KernelObject is 18, a SurfaceRecord 4.
    static_assert(sizeof(KernelObject) == 18 * sizeof(float) && sizeof(SurfaceRecord) == 4 * sizeof(float));
    const float* object_floats = reinterpret_cast<const float*>(kGathered ? job.objects : job.object);
    const float* surface_floats = reinterpret_cast<const float*>(job.surfaces);
    const MaterialT<float>& m = *job.material;
    const bool reflect_here = kReflect && job.spawn && m.refl > 0.f;
    const bool refract_here = kRefract && job.spawn && m.trans > 0.f;
    alignas(64) float lane_index[W];
    for (std::size_t l = 0; l < W; ++l) lane_index[l] = float(l);
    const B lanes = B::load_aligned(lane_index);

    for (std::size_t i = job.begin; i < job.end; i += W) {
        // The last packet may be partial: its extra lanes read padding and are never stored
        // into a stream (their local colour lands in padding too).
        const auto active = lanes < B(float(job.end - i));
        const Vec3T<B> o{B::load_unaligned(job.ox + i), B::load_unaligned(job.oy + i), B::load_unaligned(job.oz + i)};
        const Vec3T<B> d{B::load_unaligned(job.dx + i), B::load_unaligned(job.dy + i), B::load_unaligned(job.dz + i)};
        const B t = B::load_unaligned(job.t + i);
        const ColorT<B> w{B::load_unaligned(job.wr + i), B::load_unaligned(job.wg + i), B::load_unaligned(job.wb + i)};

        // The object of each lane: broadcast from the run's record, or gathered per lane.
        std::conditional_t<kGathered, LaneRows<B>, BroadcastRows<B>> rows;
        B param;
        ColorT<B> color;
        if constexpr (kGathered) {
            const I ids = I::load_unaligned(job.ids + i);  // padding lanes hold id 0
            const I at = ids * I(18), sat = ids * I(4);
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
        const B cone_in = B::load_unaligned(job.cone + i);
        const B cone = cone_in + B(job.spread) * t;
        ColorT<B> base;
        Vec3T<B> n_out;
        if (kLit || m.checker)
            n_out = apply_normal(rows, kind == ShapeKind::Mesh && !kGathered ? mesh_normals<B>(job, i)
                                                                              : canonical_normal(kind, pc, param));
        if (m.checker)
            base = surface_color(m, color, p, n_out, footprint_width(cone_in, B(job.spread), t, dot(d, n_out)));
        else base = color;
        ColorT<B> local;
        if constexpr (!kLit) {
            local = mul(w, base);
        } else {
            const auto facing = dot(n_out, d) < B(0.f);
            const Vec3T<B> n = select3(facing, n_out, -n_out);
            local = mul(w, ambient_light(job.degree, job.ambient, m, base));
            Vec3T<B> shadow_origin{};
            if constexpr (kShadows) shadow_origin = offset_ray_origin(p, n, o);
            for (std::size_t li = 0; li < job.n_lights; ++li) {
                const LightT<float>& l = job.lights[li];
                const LightSample<B> ls = sample_light(l, p);
                const DirectLight<B> dl = direct_light(job.degree, m, base, n, d, l, ls);
                const auto send = dl.lit && active;
                if (xsimd::none(send)) continue;
                if constexpr (kShadows) {
                    const Vec3T<B> to =
                        l.kind == LightKind::Directional ? ls.to_light : splat<B>(l.pos) - shadow_origin;
                    const ColorT<B> c = mul(w, dl.color);
                    const unsigned bits = lane_bits(send);
                    const ShadowAppend& sa = job.shadows;
                    const std::size_t j = *sa.count;
                    compress_store(shadow_origin.x, bits, sa.ox + j);
                    compress_store(shadow_origin.y, bits, sa.oy + j);
                    compress_store(shadow_origin.z, bits, sa.oz + j);
                    compress_store(to.x, bits, sa.dx + j);
                    compress_store(to.y, bits, sa.dy + j);
                    compress_store(to.z, bits, sa.dz + j);
                    compress_store(ls.t_max, bits, sa.t_max + j);
                    compress_store(c.x, bits, sa.cr + j);
                    compress_store(c.y, bits, sa.cg + j);
                    compress_store(c.z, bits, sa.cb + j);
                    *sa.count = j + compress_store(xsimd::batch<std::int32_t, Arch>::load_unaligned(job.pixel + i), bits,
                                                   sa.pixel + j);
                } else {
                    local = local + mul(w, dl.color);
                }
            }
            if (reflect_here) append(job, i, active, offset_ray_origin(p, n, o), reflect(d, n), w * B(m.refl), cone, RayKind::Reflected);
            if (refract_here) {
                const Vec3T<B> tr = refract(d, n_out, m.ior);
                const auto out_side = dot(tr, n_out) > B(0.f);
                append(job, i, active, offset_ray_origin(p, select3(out_side, n_out, -n_out), o), tr, w * B(m.trans),
                       cone, RayKind::Refracted);
            }
        }
        local.x.store_unaligned(job.lr + i);
        local.y.store_unaligned(job.lg + i);
        local.z.store_unaligned(job.lb + i);
    }
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
