#pragma once
// The SIMD generate kernel: camera rays for a chunk of pixels, given per-ray pixel corners,
// sample keys and lattice cells prepared by the scalar driver (integer bookkeeping that does
// not vectorise). The sampling and camera formulas are render/'s, instantiated for batches.
// Included only by kernels/isa_*.cpp, inside their own namespace.
#include <xsimd/xsimd.hpp>

#include <cstdint>
#include <limits>

#include "kernels/shade_job.h"
#include "render/sampling.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// render/sampling.h's pixel_sample for rays [i, i + W) of the job.
template <class B, class U>
inline PixelSampleT<B> job_pixel_sample(const GenerateJob& job, std::size_t i) {
    if (!job.jitter) return {B(job.fixed_offset), B(job.fixed_offset)};
    if (job.sequence) return sequence_sample(U::load_aligned(job.key_pixel + i), U::load_aligned(job.key_sample + i));
    U h1, h2;
    sample_hashes(U::load_aligned(job.key_pixel + i), U::load_aligned(job.key_sample + i), h1, h2);
    return lattice_sample(SamplePattern(job.pattern), B::load_aligned(job.cell_x + i), B::load_aligned(job.cell_y + i),
                          B(job.cols), B(job.rows), unit_from_hash(h1), unit_from_hash(h2));
}

/// Writes camera rays [i, i + W): origin o, direction d, unbounded, weight 1/spp. The cone
/// starts as a point (the pinhole's; a thin lens keeps it, docs/scene-format.md).
template <class B>
inline void store_camera_rays(const GenerateJob& job, std::size_t i, const Vec3T<B>& o, const Vec3T<B>& d) {
    const RayAppend& r = job.out;
    o.x.store_aligned(r.ox + i);
    o.y.store_aligned(r.oy + i);
    o.z.store_aligned(r.oz + i);
    d.x.store_aligned(r.dx + i);
    d.y.store_aligned(r.dy + i);
    d.z.store_aligned(r.dz + i);
    B(std::numeric_limits<float>::infinity()).store_aligned(r.t_max + i);
    B(job.weight).store_aligned(r.wr + i);
    B(job.weight).store_aligned(r.wg + i);
    B(job.weight).store_aligned(r.wb + i);
    B(0.f).store_aligned(r.cone + i);
}

template <class Arch>
void generate_rays(const GenerateJob& job) {
    using B = xsimd::batch<float, Arch>;
    using U = xsimd::batch<std::uint32_t, Arch>;
    constexpr std::size_t W = B::size;
    const CameraRays<float>& cam = *job.camera;
    const Vec3T<B> o{B(cam.origin.x), B(cam.origin.y), B(cam.origin.z)};
    for (std::size_t i = 0; i < job.count; i += W) {  // arrays are padded to whole packets
        const PixelSampleT<B> s = job_pixel_sample<B, U>(job, i);
        store_camera_rays(job, i, o,
                          cam.direction(B::load_aligned(job.px + i) + s.x, B::load_aligned(job.py + i) + s.y));
    }
}

/// The thin-lens camera (aperture > 0), a separate entry chosen once per scene: the rays of
/// generate_rays leave from a lens point (render/sampling.h's lens_sample, a packet at a
/// time) towards the plane in focus (CameraRays::lens_ray).
template <class Arch>
void generate_lens_rays(const GenerateJob& job) {
    using B = xsimd::batch<float, Arch>;
    using U = xsimd::batch<std::uint32_t, Arch>;
    constexpr std::size_t W = B::size;
    const CameraRays<float>& cam = *job.camera;
    for (std::size_t i = 0; i < job.count; i += W) {
        const PixelSampleT<B> s = job_pixel_sample<B, U>(job, i);
        U h1, h2;
        lens_hashes(U::load_aligned(job.key_pixel + i), U::load_aligned(job.key_sample + i), h1, h2);
        const PixelSampleT<B> q = lattice_sample(SamplePattern(job.pattern), B::load_aligned(job.lens_cell_x + i),
                                                 B::load_aligned(job.lens_cell_y + i), B(job.cols), B(job.rows),
                                                 unit_from_hash(h1), unit_from_hash(h2));
        const PixelSampleT<B> disc = concentric_disc(q.x, q.y);
        Vec3T<B> o, d;
        cam.lens_ray(B::load_aligned(job.px + i) + s.x, B::load_aligned(job.py + i) + s.y, disc.x, disc.y, o, d);
        store_camera_rays(job, i, o, d);
    }
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
