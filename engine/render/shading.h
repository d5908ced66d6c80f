#pragma once
// The handout's local lighting by degree, reflection, refraction and ray-origin offsets,
// written once for V = double (recursive baseline), float and xsimd float batches (the
// stream engine's shade kernels). Materials and lights are per-object scalars, broadcast
// into lanes; everything that varies per ray goes through select(), never a branch.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/vec3.h"
#include "core/vec_lanes.h"
#include "lights/lights.h"
#include "render/render_stats.h"
#include "render/sampling.h"
#include "scene/scene.h"
#include "simd/isa_namespace.h"
#include "simd/lanes.h"

namespace streamrt {

/// A material in the engine's precision. The object's own colour (Object::color) is passed
/// beside it wherever a surface colour is needed.
template <class T>
struct MaterialT {
    ColorT<T> checker_color;
    T ambi, diff, spec, shininess, refl, trans, ior, inv_cell;
    bool checker;
    /// Below this R.V the highlight spec (R.V)^shininess is under 1e-5 (far below 1/255), so
    /// it is not computed: pow is the costliest call of the shade stage.
    T spec_cutoff = T(0);
    /// Added to p / cell before the checker parity: the stream engine renders relative to
    /// the eye and puts (eye / cell) mod 2 here; zero for world coordinates.
    Vec3T<T> cell_offset{T(0), T(0), T(0)};
    /// Fresnel: set for a fresnel=true material that is a dielectric (trans > 0, ior != 1;
    /// at ior = 1 there is no interface and nothing to reflect); r0 = ((ior-1)/(ior+1))^2.
    bool fresnel = false;
    T r0 = T(0);
    // Textures (render/texture.h): the image's levels replace the object's colour; set by
    // each engine from Scene::textures (empty: no texture, today's code).
    TextureView texture{};
    T uv_scale = T(1);
    /// vertex_colors=true: a mesh's interpolated vertex colours replace the object's colour
    /// (the scene reader allows it on meshes only, without a texture).
    bool vertex_colors = false;
    /// emission=: the surface's own radiance, added at every hit from degree 1 (shade_hit);
    /// `emits` when it is not black.
    ColorT<T> emission{T(0), T(0), T(0)};
    bool emits = false;

    /// The engine's form of a scene material; each engine then sets what depends on its
    /// tables (texture, cell_offset).
    static MaterialT from(const Material& m) {
        MaterialT r{};
        r.checker_color = {T(m.checker_color.x), T(m.checker_color.y), T(m.checker_color.z)};
        r.ambi = T(m.ambi);
        r.diff = T(m.diff);
        r.spec = T(m.spec);
        r.shininess = T(m.shininess);
        r.refl = T(m.refl);
        r.trans = T(m.trans);
        r.ior = T(m.ior);
        r.inv_cell = T(1.0 / m.cell);
        r.checker = m.checker;
        r.spec_cutoff = T(m.spec > 0 && m.shininess > 0
                              ? std::min(1.0, std::pow(std::min(1.0, 1e-5 / m.spec), 1.0 / m.shininess))
                              : 0.0);
        r.fresnel = m.fresnel && m.trans > 0 && m.ior != 1.0;
        const double r0 = (m.ior - 1.0) / (m.ior + 1.0);
        r.r0 = T(r.fresnel ? r0 * r0 : 0.0);
        r.uv_scale = T(m.uv_scale);
        r.vertex_colors = m.vertex_colors;
        r.emission = {T(m.emission.x), T(m.emission.y), T(m.emission.z)};
        r.emits = m.emission != glm::dvec3(0.0);
        return r;
    }
};

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

namespace detail {
/// G(x) = integral from 0 to x of [floor(u) is odd] du; G(x + 2) = G(x) + 1.
template <class V>
inline V odd_cells_integral(const V& x) {
    using namespace simd;
    using std::floor;
    const V pairs = floor(x * V(0.5));
    return pairs + max(x - V(2) * pairs - V(1), V(0));
}
/// Share of [c - half, c + half] covered by odd cells. The pattern has period 2, so c is first
/// brought into [0, 2): the difference of G then stays accurate far from the origin. Boxes
/// narrower than 1e-4 cell fall back to a point sample (and avoid 0 / 0).
template <class V>
inline V odd_share(const V& c, const V& half) {
    using namespace simd;
    using std::floor;
    const V r = c - V(2) * floor(c * V(0.5));
    const V point = select(r >= V(1), V(1), V(0));
    const auto wide = half > V(1e-4);
    const V h = select(wide, half, V(1));
    const V box = (odd_cells_integral(r + h) - odd_cells_integral(r - h)) / (V(2) * h);
    return select(wide, box, point);
}
}  // namespace detail

/// Checker cells of side `cell` centred on multiples of cell (so y = 0 floors sit mid-cell,
/// where float noise cannot flip the parity), box-filtered over the ray's footprint: a disc of
/// diameter `footprint` (world units) in the surface's tangent plane, n its unit normal. The
/// parity of three axes combines as p = a + b - 2ab (the chance that an odd number of them is
/// odd), the closed form of a box filter applied to the 3-D checker. Far away, where a pixel
/// covers many cells, this converges to the average colour instead of aliasing, and the
/// float and double engines agree there.
/// A textured material (MaterialT::texture) has `color` already replaced by its texture's
/// filtered colour at the hit: each engine computes it before shade_hit, from the canonical
/// hit point it holds (render/texture.h texture_color), only when the material has a texture
/// (one branch per material, or per run of rays in the SIMD kernel).
template <class V, class T, class C>
inline ColorT<V> surface_color(const MaterialT<T>& m, const ColorT<C>& color, const Vec3T<V>& p, const Vec3T<V>& n,
                               const V& footprint) {
    using namespace simd;
    if (!m.checker) return splat<V>(color);
    const V k(m.inv_cell), half_cell(0.5);
    const V h = half_cell * footprint * k;
    const auto extent = [&](const V& nc) { return h * sqrt(max(V(1) - nc * nc, V(0))); };
    const V fx = detail::odd_share(p.x * k + (half_cell + V(m.cell_offset.x)), extent(n.x));
    const V fy = detail::odd_share(p.y * k + (half_cell + V(m.cell_offset.y)), extent(n.y));
    const V fz = detail::odd_share(p.z * k + (half_cell + V(m.cell_offset.z)), extent(n.z));
    const V fxy = fx + fy - V(2) * fx * fy;
    const V odd = fxy + fz - V(2) * fxy * fz;
    return splat<V>(color) + (splat<V>(m.checker_color) - splat<V>(color)) * odd;
}

/// Width of a ray's footprint where it meets a surface: the cone it carries (width at its
/// origin plus `spread` radians per unit of distance; ray cones, Akenine-Moeller et al. 2019,
/// without the curvature term) stretched by 1 / |cos| of the angle of incidence.
template <class V>
inline V footprint_width(const V& cone_at_origin, const V& spread, const V& t, const V& cos_incidence) {
    using namespace simd;
    return (cone_at_origin + spread * t) / max(abs(cos_incidence), V(1e-3));
}

template <class V>
struct DirectLight {
    ColorT<V> color;  ///< zero where `lit` is false
    MaskOf<V> lit;    ///< the light reaches the side the normal faces
    /// Where `color` may be non-zero: lit, and for a material without a Lambert term (diff =
    /// 0: a pure mirror or glass) only where its highlight is above its cut-off. A shadow ray
    /// elsewhere could only carry zero, so none is cast there (the same pixels, fewer rays).
    MaskOf<V> contributes;
};

/// Direct light from one light at degree >= 1, before visibility:
/// degree 1: (N.w) Col with the light taken as white; degree >= 2: light colour x
/// (diff (N.w) Col + spec (R.V)^shininess).  n faces the viewer; view is the ray direction.
template <class V, class T>
inline DirectLight<V> direct_light(int degree, const MaterialT<T>& m, const ColorT<V>& base, const Vec3T<V>& n,
                                   const Vec3T<V>& view, const LightT<T>& l, const LightSample<V>& s) {
    using namespace simd;
    const V zero(0);
    const V ndotw = dot(n, s.w);
    const auto lit = s.reaches && (ndotw > zero);
    const V k = select(lit, ndotw, zero);
    if (degree == 1) return {base * k, lit, lit};
    ColorT<V> c = base * (V(m.diff) * k);
    const bool lambert = m.diff > T(0);  // per material: uniform over a packet
    auto contributes = lit;
    if (!lambert) contributes = lit && !lit;  // none but the highlight's lanes, below
    if (m.spec > T(0)) {
        const Vec3T<V> r = n * (V(2) * ndotw) - s.w;  // w mirrored about n
        const V rv = -dot(r, view);
        const auto shiny = lit && (rv > zero) && (rv > V(m.spec_cutoff));
        if (any(shiny)) {
            const V h = select(shiny, V(m.spec) * simd::pow(select(shiny, rv, V(1)), V(m.shininess)), zero);
            c = c + ColorT<V>{h, h, h};
        }
        if (!lambert) contributes = shiny;
    }
    return {mul(c, splat<V>(l.color)), lit, contributes};
}

/// The part of the colour that needs no light: degree 0 the flat colour, degree 1
/// alpha Col, degree >= 2 alpha ambi Col.
/// Degree 6 computes the light that the ambient term stood for (global-illumination.md), so
/// it has none.
template <class V, class T>
inline ColorT<V> ambient_light(int degree, T alpha, const MaterialT<T>& m, const ColorT<V>& base) {
    if (degree == 0) return base;
    if (degree == 1) return base * V(alpha);
    if (degree >= 6) return base * V(0);
    return base * V(alpha * m.ambi);
}

/// A direction about the unit normal n with density cos(theta) / pi (the Lambert BRDF's
/// importance), from (u1, u2) in [0, 1)^2: the concentric disc lifted onto the hemisphere
/// (Malley's method), in the frame of Duff et al. (2017): no branch, and no division by
/// zero (sign + n.z is at least 1 in magnitude, sign taking n.z's side). The disc's angle comes from
/// simd/stable_math.h, so every ISA level and the double engine get the same direction bits
/// for the same numbers, up to their precision.
template <class V>
inline Vec3T<V> cosine_direction(const Vec3T<V>& n, const V& u1, const V& u2) {
    using namespace simd;
    const PixelSampleT<V> q = concentric_disc(u1, u2);
    const V z = sqrt(max(V(1) - q.x * q.x - q.y * q.y, V(0)));
    const V sign = select(n.z >= V(0), V(1), V(-1));
    const V a = V(-1) / (sign + n.z);
    const V b = n.x * n.y * a;
    const Vec3T<V> t{V(1) + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const Vec3T<V> s{b, sign + n.y * n.y * a, -n.y};
    return normalize(t * q.x + s * q.y + n * z);
}

template <class V>
inline Vec3T<V> reflect(const Vec3T<V>& d, const Vec3T<V>& n) {
    return d - n * (V(2) * dot(d, n));
}

/// What Snell's law gives at a surface: the transmitted direction (the mirror direction on
/// total internal reflection), whether it was total, and the cosines on both sides.
template <class V>
struct Refraction {
    Vec3T<V> dir;
    MaskOf<V> tir;
    V cos_i, cos_t;  ///< incident and transmitted angles' cosines (cos_t = 0 when tir)
    V eta;           ///< n1 / n2: index on the incident side over index on the far side
};

/// Snell's law for a unit d at a surface of outward unit normal n and index ior inside.
/// Entering when d.n < 0.
template <class V, class T>
inline Refraction<V> refraction(const Vec3T<V>& d, const Vec3T<V>& n, T ior) {
    using namespace simd;
    const V cos_signed = -dot(d, n);
    const auto leaving = cos_signed < V(0);
    const V cos_i = abs(cos_signed);
    const Vec3T<V> nn = select3(leaving, -n, n);
    const V eta = select(leaving, V(ior), V(T(1) / ior));
    const V k = V(1) - eta * eta * (V(1) - cos_i * cos_i);
    const auto tir = k < V(0);
    const V cos_t = sqrt(select(tir, V(0), k));
    const Vec3T<V> t = normalize(d * eta + nn * (eta * cos_i - cos_t));
    return {select3(tir, reflect(d, nn), t), tir, cos_i, cos_t, eta};
}

/// The transmitted direction alone; on total internal reflection the mirror direction.
template <class V, class T>
inline Vec3T<V> refract(const Vec3T<V>& d, const Vec3T<V>& n, T ior, MaskOf<V>* total_internal = nullptr) {
    const Refraction<V> r = refraction(d, n, ior);
    if (total_internal) *total_internal = r.tir;
    return r.dir;
}

/// Schlick's approximation of the unpolarised Fresnel reflectance at a refraction r, with
/// r0 = ((n1 - n2) / (n1 + n2))^2: R = r0 + (1 - r0) (1 - cos)^5, where cos is the cosine in
/// the less dense medium (the incident angle when entering the denser one, the transmitted
/// angle when leaving it: Schlick's formula is written for that side); R = 1 on total
/// internal reflection.
template <class V, class T>
inline V schlick_reflectance(T r0, const Refraction<V>& r) {
    using namespace simd;
    const V c = V(1) - select(r.eta > V(1), r.cos_t, r.cos_i);
    const V c2 = c * c;
    return select(r.tir, V(1), V(r0) + V(T(1) - r0) * (c2 * c2 * c));
}

namespace detail {
/// Relative size of the ray-origin offset: 2^-17 of the magnitude (64 float ulps). The same in
/// double: the offset is part of what is rendered (a ray leaving a smooth glass mesh can meet
/// the same triangle again a few offsets away), so the recursive engine takes the stream
/// engine's, and the two agree on glass meshes (docs/performance.md, "Glass meshes: both
/// engines render the same picture").
template <class S>
inline constexpr S kOffsetRelative = S(1.0 / 131072.0);
template <class V>
inline V max_abs(const Vec3T<V>& a) {
    return simd::max(simd::abs(a.x), simd::max(simd::abs(a.y), simd::abs(a.z)));
}
}  // namespace detail

/// Whether a ray of direction d meets the surface of outward normal n_out from outside: the
/// side shade_hit lights and sends shadow rays from is n_out's then, -n_out's otherwise.
template <class V>
inline MaskOf<V> meets_outside(const Vec3T<V>& n_out, const Vec3T<V>& d) {
    return dot(n_out, d) < V(0);
}

/// Moves a hit point p off its surface along n (unit, the side the new ray leaves on) by an
/// amount proportional to the magnitude of the numbers it was computed from: the point
/// itself and the origin `from` of the ray that found it (p = from + t d carries an error of a
/// few ulps of the larger of the two), both measured from the eye `eye` (the stream engine
/// renders relative to the eye and passes 0; the recursive engine passes its eye, so both
/// move a point by the same amount wherever the scene sits in the world). In the spirit of
/// Waechter & Binder ("A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
/// Gems ch. 6), but with no absolute constant at all: their fixed 1/65536 step near the origin
/// (below 1/32) was 15% of the scene at 1e-4 units, and the offset of a component ignored the
/// size of the others (a y = 0 floor hit from 10 units away kept an error of ulps of 10 in y).
/// Scale-free, so the picture is the same at 1e-4, 1 and 1e5 units; one template for double,
/// float and batches.
template <class V, class E>
inline Vec3T<V> offset_ray_origin(const Vec3T<V>& p, const Vec3T<V>& n, const Vec3T<V>& from, const Vec3T<E>& eye) {
    using S = simd::scalar_t<V>;
    const Vec3T<V> e{V(eye.x), V(eye.y), V(eye.z)};
    const V m = simd::max(detail::max_abs(p - e), detail::max_abs(from - e));
    // Floor: the smallest normal number, so a point at the exact eye still moves.
    const V step = simd::max(m, V(std::numeric_limits<S>::min())) * V(detail::kOffsetRelative<S>);
    return p + n * step;
}

/// shade_hit's shadow_point for every surface but a smooth mesh: shadow rays leave from p.
struct KeepPoint {
    template <class V>
    const Vec3T<V>& operator()(const Vec3T<V>& p) const { return p; }
};

STREAMRT_ISA_END

/// What the shading rules take from the render settings, in the engine's precision (a data
/// type the kernels' jobs carry: outside the per-level namespaces).
template <class T>
struct ShadeRules {
    int degree;
    T ambient;  ///< alpha
    bool spawn;  ///< the depth still allows reflected and refracted children
    /// Weight cut-off: a child whose throughput is below this in every channel is not traced
    /// (image cutoff=, --cutoff); 0 traces every child, as the handout does.
    T cutoff;
    T spread;  ///< ray-cone spread per unit of distance (checker filtering)
    /// Where ray-origin offsets are measured from (offset_ray_origin): the eye; (0, 0, 0) in
    /// the stream engine, which renders relative to it.
    Vec3T<T> eye{T(0), T(0), T(0)};
    /// Degree 6: Russian roulette ends the diffuse bounce of this generation's hits with
    /// probability 1 - min(1, max channel of its throughput) (from kRouletteFromDepth on).
    bool roulette = false;
    /// Degree 6, camera rays' hits with the stratified sampler: the bounce takes its direction
    /// from first_bounce_point(key, sequence_bits); -1: from hashes.
    int sequence_bits = -1;
    /// What a ray's `throughput` is multiplied by to give its path's refl / trans / albedo
    /// product: 1 in the recursive engine, the samples a slot sums in the stream engine, whose
    /// throughput carries the sample's weight (the cut-off is scaled the same way).
    T throughput_scale = T(1);
};

/// ShadeRules::sequence_bits for hits of generation `depth` (the camera rays' are 0).
inline int first_bounce_bits(const RenderSettings& s, int depth) {
    return s.degree >= 6 && depth == 0 && s.pattern == SamplePattern::Stratified ? path_sample_bits(s.spp) : -1;
}

/// Degree 6: Russian roulette applies to the diffuse bounces of hits of this generation and
/// deeper (the camera ray's hit is generation 0). Two unconditional bounces keep the light of
/// the first indirect bounces free of roulette noise, where most of it is.
inline constexpr int kRouletteFromDepth = 2;

/// The ray that found a hit, at the hit.
template <class V>
struct ArrivingRay {
    Vec3T<V> origin, dir;  ///< dir unit
    V t;                   ///< where it hit
    V cone;                ///< its footprint width at its origin
    /// What its colour is worth in the pixel: multiplies every term it gathers. The stream
    /// engine carries the product of the weights along the path (and 1/spp); the recursive
    /// engine multiplies on the way back instead, so it passes 1 here.
    ColorT<V> weight;
    /// The product of the refl / trans weights from the camera to this ray (no 1/spp): what
    /// the cut-off compares.
    ColorT<V> throughput;
};

STREAMRT_ISA_BEGIN  // per-level names in the kernel files (simd/isa_namespace.h)

// ---- Area lights, falloff and soft spot edges (docs/scene-format.md, "Area lights and soft
// shadows"). A light is seen from p as the average, over its samples, of the handout's
// point-light term from each sample point, times `scale` (falloff, soft edge, emitter
// cosine): a tiny area light is a point light of the same colour.

/// Sample (u1, u2) in [0, 1)^2 of light l seen from p: its kind's sample (lights/), then
/// falloff=inverse_square, 1 / |p - at|^2 (directional lights, at infinity, have none).
template <class V, class T>
inline ShapedSample<V> sample_shaped_light(const LightT<T>& l, const Vec3T<V>& p, const V& u1, const V& u2) {
    using namespace simd;
    ShapedSample<V> r = visit_light(l.kind, [&](auto kind) { return decltype(kind)::template sample<V>(l, p, u1, u2); });
    if (l.inverse_square && l.kind != LightKind::Directional)
        r.scale = r.scale / max(dot(r.ls.to_light, r.ls.to_light), V(std::numeric_limits<T>::min()));
    return r;
}

/// The light of one shaped light (l.shaped: area, falloff or soft edge; light number `index`)
/// at a hit: l.samples samples, stratified on a columns x rows lattice with one point per cell
/// placed by the hashes of (the ray's key, index, sample), each a shadow ray of 1 / samples of
/// the light. Lights at a point take one sample, the point itself. Otherwise as shade_hit.
// Out of line: its sample loop's locals then stay out of shade_hit's frame, which the
// recursive engine stacks once per bounce (depth 256 under AddressSanitizer overflowed a
// worker's stack when this was inlined).
template <bool kShadows, class V, class T, class M, class Sink>
[[gnu::noinline]] inline void shade_shaped_light(const ShadeRules<T>& rules, const MaterialT<T>& m, const ColorT<V>& base,
                               const Vec3T<V>& n, const ArrivingRay<V>& ray, const LightT<T>& l,
                               std::uint32_t index, const Vec3T<V>& p, const Vec3T<V>& shadow_origin,
                               const M& active, ColorT<V>& local, Sink& sink) {
    using namespace simd;
    const bool area = l.area;
    const V share(T(1) / T(l.samples));
    const int cols = l.columns;
    const V inv_cols(T(1) / T(cols)), inv_rows(T(1) / T(l.samples / cols));
    for (int j = 0; j < l.samples; ++j) {
        V u1(T(0.5)), u2(T(0.5));
        if (area) {
            const auto key = sink.light_key();
            auto h1 = key, h2 = key;
            light_sample_hashes(key, index, std::uint32_t(j), h1, h2);
            u1 = (V(T(j % cols)) + V(unit_from_hash(h1))) * inv_cols;
            u2 = (V(T(j / cols)) + V(unit_from_hash(h2))) * inv_rows;
        }
        const ShapedSample<V> s = sample_shaped_light(l, p, u1, u2);
        const DirectLight<V> dl = direct_light(rules.degree, m, base, n, ray.dir, l, s.ls);
        const auto send = dl.contributes && active && (s.scale > V(0));
        if (!any(send)) continue;
        const ColorT<V> c = mul(ray.weight, dl.color) * (s.scale * share);
        if constexpr (kShadows) {
            const Vec3T<V> to = l.kind == LightKind::Directional ? s.ls.to_light : s.at - shadow_origin;
            if constexpr (Sink::kTestsShadowsNow) {
                if (!sink.occluded(shadow_origin, to, s.ls.t_max)) local = local + c;
            } else {
                sink.shadow(send, shadow_origin, to, s.ls.t_max, c);
            }
        } else {
            local = local + c;
        }
    }
}

/// Degree 6's diffuse bounce at a hit: a ray in a cosine-distributed direction about n (the
/// side the arriving ray is on), of weight rho = base x diff per channel. The Lambert BRDF
/// rho / pi times cos over the density cos / pi leaves rho: the direct term's diff (N.w) Col
/// per unit of light, so direct and bounced light follow one reflectance. From generation
/// kRouletteFromDepth on, the bounce survives with probability q = min(1, max channel of its
/// path's throughput) and then weighs 1 / q: unbiased, and the paths worth little end early.
template <class V, class T, class M, class Sink>
[[gnu::noinline]] inline void spawn_bounce(const ShadeRules<T>& rules, const MaterialT<T>& m, const ColorT<V>& base,
                                           const Vec3T<V>& n, const ArrivingRay<V>& ray, const Vec3T<V>& origin,
                                           const V& cone, const M& active, Sink& sink) {
    using namespace simd;
    const auto key = sink.light_key();
    auto h1 = key, h2 = key, h3 = key;
    bounce_hashes(key, h1, h2, h3);
    const ColorT<V> rho = base * V(m.diff);
    ColorT<V> weight = mul(ray.weight, rho), throughput = mul(ray.throughput, rho);
    auto send = active && (max(rho.x, max(rho.y, rho.z)) > V(0));
    if (rules.roulette) {
        const V q = min(V(1), max(throughput.x, max(throughput.y, throughput.z)) * V(rules.throughput_scale));
        send = send && (V(unit_from_hash(h3)) < q);
        const V inv = V(1) / select(q > V(0), q, V(1));
        weight = weight * inv;
        throughput = throughput * inv;
    }
    if (!any(send)) return;
    V u1 = V(unit_from_hash(h1)), u2 = V(unit_from_hash(h2));
    if (rules.sequence_bits >= 0) {
        const auto q = first_bounce_point(key, rules.sequence_bits);
        u1 = V(q.x), u2 = V(q.y);
    }
    sink.child(send, origin, cosine_direction(n, u1, u2), weight, throughput, cone, RayKind::Diffuse);
}

/// The handout's shading of one hit (or one packet of hits), written once for the recursive
/// baseline (V = double, one ray), the stream engine's scalar path (float) and its SIMD
/// kernels (float batches): the surface colour (checker), the local terms by degree (with the
/// material's emission from degree 1), shadow rays, and the reflected and refracted children
/// with their weights. What differs between
/// engines is only where the results go, the Sink:
///   sink.local(c)                                  the ray's weighted local colour, first
///   sink.shadow(send, origin, to, t_max, c)        degree 5: c reaches the pixel if the
///                                                  segment origin + s to, s in (0, t_max),
///                                                  is unblocked (lanes `send`)
///   sink.child(send, origin, dir, weight, throughput, cone, kind)   a reflected or refracted
///                                                  ray to trace (lanes `send`)
///   sink.light_key()                               the ray's light-sampling key (area
///                                                  lights only: sampling.h light_key)
/// A sink with kTestsShadowsNow (the recursive engine) answers sink.occluded(origin, to,
/// t_max) at once instead, and the unblocked light joins the local colour.
/// shadow_point(p) gives the point the shadow rays leave from, before its usual offset: p
/// itself (KeepPoint), or on a smooth mesh p lifted off the flat triangle (mesh/terminator.h,
/// for the side meets_outside gives); reflected and refracted rays still start from p. It is
/// called once, and only when some lane sends a shadow ray (a smooth mesh's lift gathers its
/// triangles' corners lane by lane).
/// The features are compile-time flags so a scene's pipeline carries no code for what it
/// lacks: kLit (degree >= 1), kShadows (degree 5), kReflect (degree >= 3 and some refl),
/// kRefract (degree >= 4 and some trans), kBounce (degree 6 and some diff: spawn_bounce).
/// p is the world hit point, n_out the unit outward normal (needed when kLit or the material
/// is a checker), color the object's colour.
template <bool kLit, bool kShadows, bool kReflect, bool kRefract, bool kBounce, class V, class T, class M, class Sink,
          class ShadowPoint = KeepPoint>
inline void shade_hit(const ShadeRules<T>& rules, const MaterialT<T>& m, const LightT<T>* lights,
                      std::size_t n_lights, const ArrivingRay<V>& ray, const Vec3T<V>& p, const Vec3T<V>& n_out,
                      const ColorT<V>& color, const M& active, Sink& sink, const ShadowPoint& shadow_point = {}) {
    using namespace simd;
    const Vec3T<V>& d = ray.dir;
    const ColorT<V> base =
        m.checker ? surface_color(m, color, p, n_out, footprint_width(ray.cone, V(rules.spread), ray.t, dot(d, n_out)))
                  : color;
    if constexpr (!kLit) {
        sink.local(mul(ray.weight, base));
        return;
    } else {
        // Light on the side the ray arrives from (a camera inside a room or a sphere sees the
        // inner faces lit).
        const Vec3T<V> n = select3(meets_outside(n_out, d), n_out, -n_out);
        ColorT<V> local = mul(ray.weight, ambient_light(rules.degree, rules.ambient, m, base));
        // The surface's own emission (a per-material branch): seen wherever the surface is,
        // directly or through mirrors and glass, but it lights nothing (no light source).
        if (m.emits) local = local + mul(ray.weight, splat<V>(m.emission));
        // The shadow rays' origin, made at the first light that sends one.
        Vec3T<V> shadow_origin{};
        bool have_origin = false;
        [[maybe_unused]] const auto make_origin = [&] {
            if (have_origin) return;
            shadow_origin = offset_ray_origin(shadow_point(p), n, ray.origin, rules.eye);
            have_origin = true;
        };
        for (std::size_t li = 0; li < n_lights; ++li) {
            const LightT<T>& l = lights[li];
            if (l.shaped) {  // uniform per light: the handout's lights never enter
                if constexpr (kShadows) make_origin();
                shade_shaped_light<kShadows>(rules, m, base, n, ray, l, std::uint32_t(li), p, shadow_origin, active,
                                             local, sink);
                continue;
            }
            const LightSample<V> ls = sample_light(l, p);
            const DirectLight<V> dl = direct_light(rules.degree, m, base, n, d, l, ls);
            const auto send = dl.contributes && active;
            if (!any(send)) continue;
            const ColorT<V> c = mul(ray.weight, dl.color);
            if constexpr (kShadows) {
                make_origin();
                // Towards the light from the moved origin, so t_max = 1 still ends at it.
                const Vec3T<V> to = l.kind == LightKind::Directional ? ls.to_light : splat<V>(l.pos) - shadow_origin;
                if constexpr (Sink::kTestsShadowsNow) {
                    if (!sink.occluded(shadow_origin, to, ls.t_max)) local = local + c;
                } else {
                    sink.shadow(send, shadow_origin, to, ls.t_max, c);
                }
            } else {
                local = local + c;
            }
        }
        sink.local(local);
        if (!rules.spawn) return;
        const V cone = ray.cone + V(rules.spread) * ray.t;
        if constexpr (kBounce) {
            if (m.diff > T(0)) {  // per material: uniform over a packet
                // From the shadow rays' point: on a smooth mesh, off the flat triangle.
                make_origin();
                spawn_bounce(rules, m, base, n, ray, shadow_origin, cone, active, sink);
            }
        }
        // A child is traced unless the cut-off is on and its throughput is below it in
        // every channel.
        const auto kept = [&](const ColorT<V>& throughput) {
            if (!(rules.cutoff > T(0))) return active;
            return active && (max(throughput.x, max(throughput.y, throughput.z)) >= V(rules.cutoff));
        };
        if constexpr (kReflect && kRefract) {
            // Fresnel (a per-material choice, uniform over a packet): the dielectric's trans
            // weight is split by the reflectance R, trans R joining the mirror weight refl and
            // trans (1 - R) going through; refl + trans stays the total, as with fixed
            // weights. On total internal reflection everything is reflected (no refracted
            // child). The stream engine builds spawn(reflect) whenever such a material exists.
            if (m.fresnel && rules.degree >= 4) {
                const Refraction<V> rf = refraction(d, n_out, m.ior);
                const V R = schlick_reflectance(m.r0, rf);
                const V w_refl = V(m.refl) + V(m.trans) * R, w_trans = V(m.trans) * (V(T(1)) - R);
                const ColorT<V> through_refl = ray.throughput * w_refl;
                sink.child(kept(through_refl), offset_ray_origin(p, n, ray.origin, rules.eye), reflect(d, n),
                           ray.weight * w_refl, through_refl, cone, RayKind::Reflected);
                const Vec3T<V> side = select3(dot(rf.dir, n_out) > V(0), n_out, -n_out);
                const ColorT<V> through_trans = ray.throughput * w_trans;
                sink.child(kept(through_trans) && !rf.tir, offset_ray_origin(p, side, ray.origin, rules.eye), rf.dir,
                           ray.weight * w_trans, through_trans, cone, RayKind::Refracted);
                return;
            }
        }
        // Fixed weights (the handout's): a reflected child of weight refl and a refracted one
        // of weight trans. On total internal reflection the refracted ray would leave from the
        // same point in the same mirror direction as the reflected one (reflect() is the same
        // about n and -n): with a reflected child, it joins it, one ray of weight refl + trans
        // instead of two identical subtrees (inside a glass mesh, where light bounces between
        // faces, that halves the rays at every total reflection).
        const bool refracts = kRefract && rules.degree >= 4 && m.trans > T(0);
        const bool reflects = kReflect && rules.degree >= 3 && (m.refl > T(0) || refracts);
        MaskOf<V> tir = V(0) != V(0);
        Vec3T<V> t = d;
        if (refracts) {
            const Refraction<V> rf = refraction(d, n_out, m.ior);
            t = rf.dir;
            if (reflects) tir = rf.tir;
        }
        if constexpr (kReflect) {
            if (reflects) {
                const V w = V(m.refl) + select(tir, V(m.trans), V(0));
                const ColorT<V> throughput = ray.throughput * w;
                sink.child(kept(throughput) && (w > V(0)), offset_ray_origin(p, n, ray.origin, rules.eye), reflect(d, n),
                           ray.weight * w, throughput, cone, RayKind::Reflected);
            }
        }
        if constexpr (kRefract) {
            if (refracts) {
                const Vec3T<V> side = select3(dot(t, n_out) > V(0), n_out, -n_out);
                const ColorT<V> throughput = ray.throughput * V(m.trans);
                sink.child(kept(throughput) && !tir, offset_ray_origin(p, side, ray.origin, rules.eye), t, ray.weight * V(m.trans),
                           throughput, cone, RayKind::Refracted);
            }
        }
    }
}

STREAMRT_ISA_END
}  // namespace streamrt
