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

template <class Arch>
void generate_rays(const GenerateJob& job) {
    using B = xsimd::batch<float, Arch>;
    using U = xsimd::batch<std::uint32_t, Arch>;
    constexpr std::size_t W = B::size;
    const CameraRays<float>& cam = *job.camera;
    const RayAppend& r = job.out;
    for (std::size_t i = 0; i < job.count; i += W) {  // arrays are padded to whole packets
        // render/sampling.h's pixel_sample, a packet at a time.
        PixelSampleT<B> s{B(0.5f), B(0.5f)};
        if (job.jitter) {
            U h1, h2;
            sample_hashes(U::load_aligned(job.key_pixel + i), U::load_aligned(job.key_sample + i), h1, h2);
            s = lattice_sample(SamplePattern(job.pattern), B::load_aligned(job.cell_x + i),
                               B::load_aligned(job.cell_y + i), B(job.cols), B(job.rows), unit_from_hash(h1),
                               unit_from_hash(h2));
        }
        const Vec3T<B> d = cam.direction(B::load_aligned(job.px + i) + s.x, B::load_aligned(job.py + i) + s.y);
        B(cam.origin.x).store_aligned(r.ox + i);
        B(cam.origin.y).store_aligned(r.oy + i);
        B(cam.origin.z).store_aligned(r.oz + i);
        d.x.store_aligned(r.dx + i);
        d.y.store_aligned(r.dy + i);
        d.z.store_aligned(r.dz + i);
        B(std::numeric_limits<float>::infinity()).store_aligned(r.t_max + i);
        B(job.weight).store_aligned(r.wr + i);
        B(job.weight).store_aligned(r.wg + i);
        B(job.weight).store_aligned(r.wb + i);
        B(0.f).store_aligned(r.cone + i);  // a pinhole: the cone starts as a point
    }
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
