#pragma once
// What a shade kernel reads and writes: a run of rays (sorted so that they all hit the same
// object) and the streams it appends to. Raw pointers only, so the per-ISA kernel files touch
// no container code (see kernels/intersect_kernel.h on why).
#include <cstddef>
#include <cstdint>

#include "kernels/kernel_object.h"
#include "kernels/ray_stream.h"
#include "mesh/mesh_view.h"
#include "render/camera_rays.h"
#include "render/shading.h"
#include "scene/scene.h"

namespace streamrt {


/// Append-only view of a RayStream (reflected and refracted rays).
struct RayAppend {
    float *ox, *oy, *oz, *dx, *dy, *dz, *t_max, *wr, *wg, *wb, *cone;
    std::int32_t* pixel;
    std::uint8_t* kind;
    std::size_t* count;
    std::uint32_t* key = nullptr;  ///< scenes with area lights: the rays' light-sampling keys
};

/// Append-only view of a ShadowStream.
struct ShadowAppend {
    float *ox, *oy, *oz, *dx, *dy, *dz, *t_max, *cr, *cg, *cb;
    std::int32_t* pixel;
    std::size_t* count;
};

/// The append views of a stream's arrays (without the keys: a stage that carries them sets them).
inline RayAppend append_view(RayStream& r) {
    return {.ox = r.ox.data(), .oy = r.oy.data(), .oz = r.oz.data(), .dx = r.dx.data(), .dy = r.dy.data(),
            .dz = r.dz.data(), .t_max = r.t_max.data(), .wr = r.wr.data(), .wg = r.wg.data(), .wb = r.wb.data(),
            .cone = r.cone.data(), .pixel = r.pixel.data(), .kind = r.kind.data(), .count = &r.count};
}
inline ShadowAppend append_view(ShadowStream& s) {
    return {.ox = s.ox.data(), .oy = s.oy.data(), .oz = s.oz.data(), .dx = s.dx.data(), .dy = s.dy.data(),
            .dz = s.dz.data(), .t_max = s.t_max.data(), .cr = s.cr.data(), .cg = s.cg.data(), .cb = s.cb.data(),
            .pixel = s.pixel.data(), .count = &s.count};
}

struct ShadeJob {
    // The slice's rays, in its own order (the stream's arrays; t is the closest hit's).
    const float *ox, *oy, *oz, *dx, *dy, *dz, *t, *wr, *wg, *wb, *cone;
    const std::int32_t* pixel;
    // The run: its j-th ray, for j in [begin, end), is ray order[j] of those arrays; order is
    // readable up to end + kMaxLanes, past the last run with the index of a hit. Reading the
    // rays through it (run_field, shade_kernel.h) replaced copying every field into run order,
    // which with its counting took a quarter of whitted's render at 16 spp.
    const std::int32_t* order;
    std::size_t begin, end;
    // The object they all hit: its record (Mi, kind, parameter, mesh), colour and material.
    // Gathered runs (scenes too large to regroup by object) share only the material and the
    // shape kind: each lane's record is read through ids[] (the last fields, shade_kernel.h).
    const KernelObject* object;
    ColorT<float> color;
    const MaterialT<float>* material;
    const LightT<float>* lights;
    std::size_t n_lights;
    ShadeRules<float> rules;  ///< degree, ambient, whether children spawn, cut-off, cone spread
    // Outputs: the weighted local colour of each ray (indexed as `order`) ...
    float *lr, *lg, *lb;
    // ... and the rays it spawns: reflected children in `next`, refracted ones in
    // `next_refracted` (a region of the same arrays that the stage joins after the last run),
    // and shadow rays, whose `pixel` field holds their hit's run position: the stage adds an
    // unblocked shadow ray's light to that hit's local colour, and the local colours into the
    // pixels after the occlusion stage. A pixel's terms then come in an order that depends on
    // its own rays alone (docs/architecture.md, "Sums in a fixed order").
    RayAppend next;
    RayAppend next_refracted;
    RayAppend next_diffuse;  ///< degree 6: the diffuse bounces, a third region of the same arrays
    ShadowAppend shadows;
    // Mesh objects only: the hit triangle and its barycentrics per ray (the slice's order); the
    // mesh and its smooth flag are the run's object's, or (gathered) each ray's object's.
    const std::int32_t* prim = nullptr;
    const float* bu = nullptr;
    const float* bv = nullptr;
    const std::int32_t* ids = nullptr;         ///< gathered: per ray (the slice's order), its object's id
    const KernelObject* objects = nullptr;     ///< gathered: every object's record, by id
    const SurfaceRecord* surfaces = nullptr;   ///< gathered: every object's colour, by id
    ShapeKind kind = ShapeKind::Sphere;        ///< gathered: the run's shape kind
    const std::uint32_t* key = nullptr;        ///< area lights, degree 6: per ray (the slice's order), its key
    bool rekey = false;  ///< degree 6: children take keys of their own (render/sampling.h child_key)
};

/// Camera rays for one chunk. Per ray (arrays padded to whole packets): the pixel's corner
/// in image coordinates, the hash keys (global pixel index, sample index) and the lattice
/// cell of the sample. Written to out[0, count).
struct GenerateJob {
    std::size_t count;
    const float *px, *py, *cell_x, *cell_y;
    const std::uint32_t *key_pixel, *key_sample;
    int pattern;  ///< SamplePattern
    bool jitter;  ///< false: every ray at fixed_offset in its pixel
    float cols, rows;
    const CameraRays<float>* camera;
    float weight;
    RayAppend out;
    /// Thin lens only (generate_lens): per ray, the sample's lattice cell on the lens
    /// (render/sampling.h's LensCells). Keys are then filled even at spp = 1.
    const float *lens_cell_x = nullptr, *lens_cell_y = nullptr;
    /// Without jitter, every ray's offset in its pixel: 0.5, the centre (spp = 1); 0, the
    /// pixel's corner (a corner run, render/sampling.h).
    float fixed_offset = 0.5f;
    /// Adaptive rounds (render/sampling.h's uses_sequence): the offset is point key_sample of
    /// the pixel's sequence (sequence_sample); the lattice is unused.
    bool sequence = false;
};
using GenerateFn = void (*)(const GenerateJob& job);

/// Shade variants, indexed by lit | shadows << 1 | reflect << 2 | refract << 3 | bounce << 4;
/// bounce (degree 6) comes with lit only: the unlit bounce variants are not built (nullptr).
inline constexpr int kShadeVariants = 32;
using ShadeFn = void (*)(const ShadeJob& job);

}  // namespace streamrt
