#pragma once
// Cutting a generation of rays into slices of whole pixels, so the rays held at once stay
// bounded whatever the depth (stages.h, trace_generation).
#include <algorithm>
#include <cstdint>
#include <vector>

#include "kernels/ray_stream.h"

namespace streamrt::stage_detail {

/// Copies rays [from, from + n) of `src` into `dst` (which then holds exactly them).
inline void copy_rays(const RayStream& src, std::size_t from, std::size_t n, RayStream& dst, bool keys) {
    dst.reserve(n);
    if (keys) {  // area lights
        dst.reserve_keys();
        std::copy_n(src.key.begin() + std::ptrdiff_t(from), n, dst.key.begin());
    }
    RayStream::for_each_array(
        [&](auto a) { std::copy_n((src.*a).begin() + std::ptrdiff_t(from), n, (dst.*a).begin()); });
    dst.count = n;
}

/// Copies ray i of `src` to place j of `dst` (every array, and the key when `keys`).
inline void move_ray(const RayStream& src, std::size_t i, RayStream& dst, std::size_t j, bool keys) {
    if (keys) dst.key[j] = src.key[i];
    dst.ox[j] = src.ox[i], dst.oy[j] = src.oy[i], dst.oz[j] = src.oz[i];
    dst.dx[j] = src.dx[i], dst.dy[j] = src.dy[i], dst.dz[j] = src.dz[i];
    dst.t_max[j] = src.t_max[i];
    dst.wr[j] = src.wr[i], dst.wg[j] = src.wg[i], dst.wb[j] = src.wb[i];
    dst.cone[j] = src.cone[i];
    dst.pixel[j] = src.pixel[i];
    dst.kind[j] = src.kind[i];
}

/// Cuts a generation of more than `cap` rays into slices of at most `cap` rays that each
/// hold all the rays of their pixels (pixels in order, as many whole pixels as fit), and
/// regroups `gen` so each slice is contiguous, keeping the rays' order within a slice. A
/// pixel with more than `cap` rays alone is cut, in stream order, into slices of its own.
/// Returns the slices' bounds in `gen` (first 0, last gen.count). `scratch` ends holding the
/// generation's former buffer. `keys`: the rays carry light-sampling keys (area lights).
inline std::vector<std::size_t> cut_into_slices(RayStream& gen, RayStream& scratch, std::size_t cap,
                                                std::size_t tile_pixels, std::vector<std::uint32_t>& pixel_rays,
                                                std::vector<std::uint32_t>& pixel_slice, bool keys) {
    pixel_rays.assign(tile_pixels, 0);
    for (std::size_t i = 0; i < gen.count; ++i) ++pixel_rays[std::size_t(gen.pixel[i])];
    // Each pixel's first slice: pixels are packed greedily, in pixel order.
    pixel_slice.assign(tile_pixels, 0);
    std::vector<std::size_t> size;  // rays per slice
    std::size_t fill = cap;         // rays in the last slice (cap: full, open a new one)
    for (std::size_t p = 0; p < tile_pixels; ++p) {
        const std::size_t n = pixel_rays[p];
        if (n == 0) continue;
        if (n > cap) {
            pixel_slice[p] = std::uint32_t(size.size());
            for (std::size_t left = n; left > 0; left -= std::min(left, cap)) size.push_back(std::min(left, cap));
            fill = cap;
            continue;
        }
        if (fill + n > cap) size.push_back(0), fill = 0;
        pixel_slice[p] = std::uint32_t(size.size() - 1);
        size.back() += n;
        fill += n;
    }
    std::vector<std::size_t> bounds(size.size() + 1, 0);
    for (std::size_t k = 0; k < size.size(); ++k) bounds[k + 1] = bounds[k] + size[k];
    // A stable counting sort by slice; a cut pixel's k-th ray goes to its slice k / cap.
    std::vector<std::size_t> at(bounds.begin(), bounds.end() - 1);
    pixel_rays.assign(tile_pixels, 0);  // now: the pixel's rays placed so far
    scratch.reserve(gen.count);
    if (keys) scratch.reserve_keys();
    for (std::size_t i = 0; i < gen.count; ++i) {
        const std::size_t p = std::size_t(gen.pixel[i]);
        move_ray(gen, i, scratch, at[pixel_slice[p] + pixel_rays[p]++ / cap]++, keys);
    }
    scratch.count = gen.count;
    std::swap(gen, scratch);
    return bounds;
}

}  // namespace streamrt::stage_detail
