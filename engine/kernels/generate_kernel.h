#pragma once
// The SIMD generate kernel: camera rays for a chunk of pixels, given per-ray pixel corners,
// sample keys and lattice cells prepared by the scalar driver (integer bookkeeping that does
// not vectorise). Included only by kernels/isa_*.cpp, inside their own namespace.
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
    using I = xsimd::batch<std::int32_t, Arch>;
    constexpr std::size_t W = B::size;
    const Vec3T<B> du{B(job.du[0]), B(job.du[1]), B(job.du[2])};
    const Vec3T<B> dv{B(job.dv[0]), B(job.dv[1]), B(job.dv[2])};
    const Vec3T<B> back{B(job.dback[0]), B(job.dback[1]), B(job.dback[2])};
    const B two(2.f), one(1.f), scale24(0x1p-24f);
    const RayAppend& r = job.out;
    for (std::size_t i = 0; i < job.count; i += W) {  // arrays are padded to whole packets
        B sx(0.5f), sy(0.5f);
        if (job.jitter) {
            U h1, h2;
            sample_hashes(U::load_aligned(job.key_pixel + i), U::load_aligned(job.key_sample + i), h1, h2);
            // Top 24 bits as a float in [0, 1), as unit_from_hash does.
            const B u = xsimd::to_float(xsimd::bitwise_cast<I>(h1 >> 8)) * scale24;
            const B v = xsimd::to_float(xsimd::bitwise_cast<I>(h2 >> 8)) * scale24;
            if (job.pattern == int(SamplePattern::Random)) {
                sx = u;
                sy = v;
            } else {
                const B ju = job.pattern == int(SamplePattern::Grid) ? B(0.5f) : u;
                const B jv = job.pattern == int(SamplePattern::Grid) ? B(0.5f) : v;
                sx = (B::load_aligned(job.cell_x + i) + ju) / B(job.cols);
                sy = (B::load_aligned(job.cell_y + i) + jv) / B(job.rows);
            }
        }
        const B px = B::load_aligned(job.px + i) + sx, py = B::load_aligned(job.py + i) + sy;
        const B u = two * px * B(job.inv_width) - one;
        const B w = one - two * py * B(job.inv_height);
        const Vec3T<B> d = normalize(du * u + dv * w + back);
        B(job.origin[0]).store_aligned(r.ox + i);
        B(job.origin[1]).store_aligned(r.oy + i);
        B(job.origin[2]).store_aligned(r.oz + i);
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
