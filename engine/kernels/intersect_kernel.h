#pragma once
// The kernel bodies, templated on the xsimd arch and the shape. Included only by the
// kernels/isa_*.cpp files, each inside its own namespace so that no inline function built
// with one level's flags can be picked by the linker for another's callers.
#include <xsimd/xsimd.hpp>

#include <array>
#include <utility>

#include <limits>

#include "kernels/generate_kernel.h"
#include "kernels/kernel_table.h"
#include "kernels/mesh_kernel.h"
#include "kernels/shade_kernel.h"
#include "shapes/shapes.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// The precision each shape is solved in, as it declares (Shape::Compute): float, except the
/// torus, whose quartic needs double lanes (8 per AVX-512 register instead of 16).
template <class Shape>
struct ComputeType { using type = typename Shape::Compute; };

template <class B>
struct RayPacket {
    Vec3T<B> o, d;
};

template <class B>
inline B load_lanes(const float* p) {
    return B::load_aligned(p);  // converts float -> double for double batches
}

/// World ray -> object's canonical space with Mi (core/transform.h's helpers, the same
/// evaluation order as the shade stage and the baseline).
template <class B, class T>
inline RayPacket<B> to_canonical(const RayPacket<B>& r, const ObjectXf& ob) {
    struct Rows {
        const float* m;
        B operator[](int i) const { return B(T(m[i])); }
    } rows{ob.m};
    return {apply_point(rows, r.o), apply_vector(rows, r.d)};
}

/// Writes a packet's closest hits back: t into t_max and the object id, for the lanes that
/// found one (id >= 0) among the first `count - i` rays.
template <class B>
inline void store_closest(RayView& rays, std::int32_t* object, std::size_t i, const B& best, const B& best_id) {
    using T = typename B::value_type;
    constexpr std::size_t W = B::size;
    alignas(64) T t_out[W], id_out[W];
    best.store_aligned(t_out);
    best_id.store_aligned(id_out);
    for (std::size_t l = 0; l < W && i + l < rays.count; ++l) {
        if (id_out[l] >= T(0)) {
            rays.t_max[i + l] = float(t_out[l]);
            object[i + l] = static_cast<std::int32_t>(id_out[l]);
        }
    }
}

/// The lanes of the packet that meet the box within (0, best). Slab test with the
/// NaN-tolerant min/max of the cube (a zero direction component on a slab face gives 0 * inf).
template <class B, class T>
inline auto lanes_meeting_box(const RayPacket<B>& r, const Vec3T<B>& inv, const ObjectBounds& box, const B& best) {
    B t_near(T(0)), t_far = best;
    const B o[3] = {r.o.x, r.o.y, r.o.z}, iv[3] = {inv.x, inv.y, inv.z};
    for (int a = 0; a < 3; ++a) {
        const B ta = (B(T(box.lo[a])) - o[a]) * iv[a];
        const B tb = (B(T(box.hi[a])) - o[a]) * iv[a];
        const auto ordered = ta < tb;
        const B lo = xsimd::select(ordered, ta, tb), hi = xsimd::select(ordered, tb, ta);
        t_near = xsimd::select(lo > t_near, lo, t_near);
        t_far = xsimd::select(hi < t_far, hi, t_far);
    }
    return t_near <= t_far;
}

/// Whether any lane of the packet meets the box within (0, best).
template <class B, class T>
inline bool packet_meets_box(const RayPacket<B>& r, const Vec3T<B>& inv, const ObjectBounds& box, const B& best) {
    return xsimd::any(lanes_meeting_box<B, T>(r, inv, box, best));
}

template <class Arch, class Shape>
void closest_hit_impl(RayView rays, std::int32_t* object, const ObjectXf* objs, const ObjectBounds* bounds,
                      std::size_t n_objs) {
    using T = typename ComputeType<Shape>::type;
    using B = xsimd::batch<T, Arch>;
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;
    // A double-precision shape can return a t outside float's range: beyond it for a
    // denormal direction (a normal double), below it for a huge one (|d| ~ 3e38). Stored into
    // the float stream they became +inf or 0 with an object id: a hit at infinity or on the
    // ray origin. Such t are misses.
    const B t_limit(T(std::numeric_limits<float>::max())), t_floor(T(std::numeric_limits<float>::min()));
    for (std::size_t i = 0; i < rays.count; i += W) {  // padding makes the last packet safe
        const RayPacket<B> r{{load_lanes<B>(rays.ox + i), load_lanes<B>(rays.oy + i), load_lanes<B>(rays.oz + i)},
                             {load_lanes<B>(rays.dx + i), load_lanes<B>(rays.dy + i), load_lanes<B>(rays.dz + i)}};
        B best = load_lanes<B>(rays.t_max + i);
        const B start = best;
        Vec3T<B> inv{};
        if (bounds) inv = {B(T(1)) / r.d.x, B(T(1)) / r.d.y, B(T(1)) / r.d.z};
        // Ids travel as T lanes (exact below 2^24 objects in float) so that the select shares
        // the distance mask's type at every width.
        B best_id(T(-1));
        for (std::size_t k = 0; k < n_objs; ++k) {
            if (bounds && !packet_meets_box<B, T>(r, inv, bounds[k], best)) continue;
            const RayPacket<B> c = to_canonical<B, T>(r, objs[k]);
            const B t = Shape::template hit_t<B>(c.o, c.d, B(T(objs[k].param)), B(T(0)), best);
            const auto closer = (t < best) && (t <= t_limit) && (t >= t_floor);
            best = xsimd::select(closer, t, best);
            best_id = xsimd::select(closer, B(T(objs[k].id)), best_id);
        }
        if (xsimd::any(best < start)) store_closest(rays, object, i, best, best_id);
    }
}

template <class Arch, class Shape>
void any_hit_impl(RayView rays, const ObjectXf* objs, const ObjectBounds* bounds, std::size_t n_objs) {
    using T = typename ComputeType<Shape>::type;
    using B = xsimd::batch<T, Arch>;
    constexpr std::size_t W = B::size;
    const simd::FlushDenormals ftz;
    for (std::size_t i = 0; i < rays.count; i += W) {
        B t_max = load_lanes<B>(rays.t_max + i);
        auto open = t_max > B(T(0));  // lanes not yet blocked (padding lanes have t_max < 0)
        if (!xsimd::any(open)) continue;
        const RayPacket<B> r{{load_lanes<B>(rays.ox + i), load_lanes<B>(rays.oy + i), load_lanes<B>(rays.oz + i)},
                             {load_lanes<B>(rays.dx + i), load_lanes<B>(rays.dy + i), load_lanes<B>(rays.dz + i)}};
        Vec3T<B> inv{};
        if (bounds) inv = {B(T(1)) / r.d.x, B(T(1)) / r.d.y, B(T(1)) / r.d.z};
        for (std::size_t k = 0; k < n_objs; ++k) {
            if (bounds && !packet_meets_box<B, T>(r, inv, bounds[k], t_max)) continue;
            const RayPacket<B> c = to_canonical<B, T>(r, objs[k]);
            const B t = Shape::template hit_t<B>(c.o, c.d, B(T(objs[k].param)), B(T(0)), t_max);
            open = open && !(t < t_max);
            t_max = xsimd::select(open, t_max, B(T(0)));
            if (!xsimd::any(open)) break;  // early exit: the whole packet is in shadow
        }
        alignas(64) T out[W];
        t_max.store_aligned(out);
        for (std::size_t l = 0; l < W && i + l < rays.count; ++l)
            if (out[l] <= T(0)) rays.t_max[i + l] = 0.f;
    }
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE

#include "kernels/csg_kernel.h"  // after the packet helpers above, which it uses

namespace streamrt::STREAMRT_ISA_NAMESPACE {

template <class Arch, class Shape>
void closest_hit(RayView rays, std::int32_t* object, const ObjectXf* objs, std::size_t n_objs) {
    closest_hit_impl<Arch, Shape>(rays, object, objs, nullptr, n_objs);
}
template <class Arch, class Shape>
void any_hit(RayView rays, const ObjectXf* objs, std::size_t n_objs) {
    any_hit_impl<Arch, Shape>(rays, objs, nullptr, n_objs);
}

#if defined(__AVX512F__) && defined(__AVX512BW__)
/// A closest-hit stream whose packets that have scattered hold enough live rays walks those
/// rays whole (mesh_stream_kernel.h) instead of packet by packet: at least kStreamWalkRays, and
/// kStreamWalkRaysPerRoot x sqrt(triangles) of its largest mesh (a larger tree shares each node
/// among fewer of the rays). Measured on a glass mesh's deep rays (docs/performance.md, "Whole
/// streams through the tree"): walked 256 at a time 1.05 - 1.33x the engine's best walk on the
/// 3.7k-triangle bunny, 0.70 - 0.88x on the 235k-triangle one, which needs thousands.
inline constexpr std::size_t kStreamWalkRays = 256;
inline constexpr double kStreamWalkRaysPerRoot = 6.0;

/// mesh_closest_impl's rays in packets that have scattered (scattered_packet_lanes, in world
/// space), walked whole object by object; the other packets go to packet(i). False (nothing
/// done) when too few rays scattered (kStreamWalkRays). The memory check counts its buffers
/// (kernels/stream_walk_memory.h).
template <class Packet>
bool mesh_closest_streamed(RayView rays, std::int32_t* object, const ObjectXf* objs, std::size_t n_objs,
                           Packet&& packet) {
    using namespace mesh_detail;
    using B = xsimd::batch<float, xsimd::avx512bw>;
    constexpr std::size_t W = B::size;
    static thread_local RawBuffer<std::uint32_t> list_buf, pool;
    static thread_local RawBuffer<std::uint8_t> scattered_buf;
    static thread_local RawBuffer<float> canonical, inverse, keep_uv;
    static thread_local RawBuffer<std::int32_t> keep_prim;
    const std::size_t packets = (rays.count + W - 1) / W;
    std::uint32_t* list = list_buf.reserve(rays.count);
    std::uint8_t* scattered = scattered_buf.reserve(packets);
    std::size_t n = 0;
    for (std::size_t p = 0; p < packets; ++p) {
        const std::size_t i = p * W;
        const Vec3T<B> d{B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i), B::load_aligned(rays.dz + i)};
        const auto live = B::load_aligned(rays.t_max + i) > B(0.f);
        scattered[p] = scattered_packet_lanes(d, live, rays.single_ray_lanes) > 0;
        if (!scattered[p]) continue;
        for (std::uint32_t bits = movemask_bits(live); bits; bits &= bits - 1) {
            const std::size_t l = std::size_t(std::countr_zero(bits));
            if (i + l < rays.count) list[n++] = std::uint32_t(i + l);
        }
    }
    std::size_t need = kStreamWalkRays;
    for (std::size_t k = 0; k < n_objs; ++k)
        if (objs[k].mesh)
            need = std::max(need, std::size_t(kStreamWalkRaysPerRoot * std::sqrt(double(objs[k].mesh->n_tris))));
    if (n < need) return false;
    for (std::size_t p = 0; p < packets; ++p)
        if (!scattered[p]) packet(p * W);
    const std::size_t span = packets * W;
    float* c = canonical.reserve(6 * span);
    float* uv = keep_uv.reserve(2 * n);
    std::int32_t* prim = keep_prim.reserve(n);
    const StreamWalkRays walk_rays{c, c + span, c + 2 * span, c + 3 * span, c + 4 * span, c + 5 * span,
                                   rays.t_max, rays.prim, rays.bu, rays.bv};
    for (std::size_t k = 0; k < n_objs; ++k) {
        if (!objs[k].mesh) continue;
        for (std::size_t p = 0; p < packets; ++p) {
            if (!scattered[p]) continue;
            const std::size_t i = p * W;
            const RayPacket<B> r{{B::load_aligned(rays.ox + i), B::load_aligned(rays.oy + i), B::load_aligned(rays.oz + i)},
                                 {B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i), B::load_aligned(rays.dz + i)}};
            const RayPacket<B> cr = to_canonical<B, float>(r, objs[k]);
            cr.o.x.store_unaligned(c + i), cr.o.y.store_unaligned(c + span + i), cr.o.z.store_unaligned(c + 2 * span + i);
            cr.d.x.store_unaligned(c + 3 * span + i), cr.d.y.store_unaligned(c + 4 * span + i),
                cr.d.z.store_unaligned(c + 5 * span + i);
        }
        // The walk marks a ray it gave a closer hit by its triangle; a ray it did not keeps its
        // hit on an earlier object (at the same t that one stays, as in the packets' loop).
        for (std::size_t j = 0; j < n; ++j) {
            const std::uint32_t i = list[j];
            prim[j] = rays.prim[i], uv[2 * j] = rays.bu[i], uv[2 * j + 1] = rays.bv[i];
            rays.prim[i] = -1;
        }
        StreamWalker(*objs[k].mesh, walk_rays, inverse, pool, span).walk(list, n);
        for (std::size_t j = 0; j < n; ++j) {
            const std::uint32_t i = list[j];
            if (rays.prim[i] >= 0) object[i] = objs[k].id;
            else rays.prim[i] = prim[j], rays.bu[i] = uv[2 * j], rays.bv[i] = uv[2 * j + 1];
        }
    }
    return true;
}
#endif

/// Closest hit against mesh objects: each packet, brought into a mesh's canonical space by
/// its Mi like the canonical shapes, walks that mesh's own hierarchy (kernels/mesh_kernel.h).
/// With `bounds` (the flat scene's padded world boxes, stream_scene.cpp) a packet that misses
/// a mesh's box skips its transform and root node: one slab test instead of 8 boxes and a
/// matrix (docs/performance.md, "Design choices", a mesh's box before its walk: the glass bunny's shadow
/// rays 0.81x, a scene of several meshes 0.61x).
template <class Arch>
void mesh_closest_impl(RayView rays, std::int32_t* object, const ObjectXf* objs, const ObjectBounds* bounds,
                       std::size_t n_objs) {
    using B = xsimd::batch<float, Arch>;
    constexpr std::size_t W = B::size;
    const auto packet = [&](std::size_t i) {
        const RayPacket<B> r{{B::load_aligned(rays.ox + i), B::load_aligned(rays.oy + i), B::load_aligned(rays.oz + i)},
                             {B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i), B::load_aligned(rays.dz + i)}};
        B best = B::load_aligned(rays.t_max + i);
        const B start = best;
        B best_id(-1.f);
        Vec3T<B> inv{};
        if (bounds) inv = {B(1.f) / r.d.x, B(1.f) / r.d.y, B(1.f) / r.d.z};
        for (std::size_t k = 0; k < n_objs; ++k) {
            if (!objs[k].mesh) continue;
            if (bounds && !packet_meets_box<B, float>(r, inv, bounds[k], best)) continue;
            const RayPacket<B> c = to_canonical<B, float>(r, objs[k]);
            const B before = best;
            mesh_closest_packet(*objs[k].mesh, c.o, c.d, best, rays.prim ? rays.prim + i : nullptr,
                                rays.bu ? rays.bu + i : nullptr, rays.bv ? rays.bv + i : nullptr,
                                std::max(objs[k].mesh->single_ray_lanes,
                                         scattered_packet_lanes(c.d, best > B(0.f),
                                                                hybrid_lanes_for(*objs[k].mesh, rays.single_ray_lanes))));
            best_id = xsimd::select(best < before, B(float(objs[k].id)), best_id);
        }
        if (xsimd::any(best < start)) store_closest(rays, object, i, best, best_id);
    };
#if defined(__AVX512F__) && defined(__AVX512BW__)
    // The rays of packets that have scattered, walked whole when they are many (from the
    // hybrid's generation on: single_ray_lanes > 0).
    if constexpr (W == 16)
        if (rays.single_ray_lanes > 0 && rays.prim && rays.bu && rays.bv && rays.count >= kStreamWalkRays &&
            mesh_closest_streamed(rays, object, objs, n_objs, packet))
            return;
#endif
    for (std::size_t i = 0; i < rays.count; i += W) packet(i);
}

/// Any hit against mesh objects (shadow rays): t_max = 0 for blocked rays; `bounds` as above.
template <class Arch>
void mesh_any_impl(RayView rays, const ObjectXf* objs, const ObjectBounds* bounds, std::size_t n_objs) {
    using B = xsimd::batch<float, Arch>;
    constexpr std::size_t W = B::size;
    for (std::size_t i = 0; i < rays.count; i += W) {
        B t_max = B::load_aligned(rays.t_max + i);
        auto open = t_max > B(0.f);
        if (!xsimd::any(open)) continue;
        const RayPacket<B> r{{B::load_aligned(rays.ox + i), B::load_aligned(rays.oy + i), B::load_aligned(rays.oz + i)},
                             {B::load_aligned(rays.dx + i), B::load_aligned(rays.dy + i), B::load_aligned(rays.dz + i)}};
        Vec3T<B> inv{};
        if (bounds) inv = {B(1.f) / r.d.x, B(1.f) / r.d.y, B(1.f) / r.d.z};
        for (std::size_t k = 0; k < n_objs && xsimd::any(open); ++k) {
            if (!objs[k].mesh) continue;
            // Closed lanes already hold t_max <= 0 (set below, or inert from the start).
            if (bounds && !packet_meets_box<B, float>(r, inv, bounds[k], t_max)) continue;
            const RayPacket<B> c = to_canonical<B, float>(r, objs[k]);
            open = open && !mesh_any_packet(*objs[k].mesh, c.o, c.d, t_max, open, objs[k].mesh->single_ray_lanes);
            t_max = xsimd::select(open, t_max, B(0.f));
        }
        alignas(64) float out[W];
        t_max.store_aligned(out);
        for (std::size_t l = 0; l < W && i + l < rays.count; ++l)
            if (out[l] <= 0.f) rays.t_max[i + l] = 0.f;
    }
}

template <class Arch>
void mesh_closest_hit(RayView rays, std::int32_t* object, const ObjectXf* objs, std::size_t n_objs) {
    mesh_closest_impl<Arch>(rays, object, objs, nullptr, n_objs);
}
template <class Arch>
void mesh_any_hit(RayView rays, const ObjectXf* objs, std::size_t n_objs) {
    mesh_any_impl<Arch>(rays, objs, nullptr, n_objs);
}

/// Shade variant k (ShadeFn's index, kernels/shade_job.h); the bounce variants without
/// lighting do not exist (degree 6 is lit).
template <class Arch, int k, bool kGathered>
constexpr ShadeFn shade_variant() {
    if constexpr ((k & 16) && !(k & 1)) return nullptr;
    else return &shade_run<Arch, bool(k & 1), bool(k & 2), bool(k & 4), bool(k & 8), bool(k & 16), kGathered>;
}
template <class Arch, bool kGathered, int... k>
constexpr std::array<ShadeFn, kShadeVariants> shade_variants(std::integer_sequence<int, k...>) {
    return {shade_variant<Arch, k, kGathered>()...};
}
/// The per-kind columns come from the registry (shapes/shapes.h): the canonical shapes in
/// ShapeKind order, then the mesh kernels (Mesh is the last kind).
template <class Arch, class... S>
KernelTable make_table(Isa isa, const char* name, ShapeList<S...>) {
    return KernelTable{isa,
                       name,
                       int(xsimd::batch<float, Arch>::size),
                       {&closest_hit<Arch, S>..., &mesh_closest_hit<Arch>},
                       {&any_hit<Arch, S>..., &mesh_any_hit<Arch>},
                       {&closest_hit_impl<Arch, S>..., &mesh_closest_impl<Arch>},
                       {&any_hit_impl<Arch, S>..., &mesh_any_impl<Arch>},
                       shade_variants<Arch, false>(std::make_integer_sequence<int, kShadeVariants>{}),
                       shade_variants<Arch, true>(std::make_integer_sequence<int, kShadeVariants>{}),
                       &generate_rays<Arch>,
                       &generate_lens_rays<Arch>,
                       &csg_closest<Arch>,
                       &csg_any<Arch>};
}

template <class Arch>
KernelTable make_table(Isa isa, const char* name) {
    return make_table<Arch>(isa, name, CanonicalShapes{});
}

#undef SHADE_VARIANT
#undef SHADE_GATHERED

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
