#pragma once
// The hierarchy traversal kernels (engine/accel), compiled per x86-64 level like the shape
// kernels (kernels/isa_<level>_accel.cpp) and picked at run time with the same Isa.
#include <cstddef>
#include <cstdint>

#include "accel/bvh.h"
#include "kernels/kernel_table.h"
#include "kernels/ray_stream.h"

namespace streamrt {

/// What the traversal kernels read: the wide nodes and the leaf-ordered objects.
struct AccelView {
    const accel::WideNode* nodes;
    const KernelObject* prims;  ///< leaf order: the leaves index it
};

/// Closest hit through the hierarchy: as ClosestHitFn (shrinks t_max, writes the object id of
/// rays that found a closer hit).
using BvhClosestFn = void (*)(const AccelView& bvh, RayView rays, std::int32_t* object);
/// Any hit through the hierarchy: as AnyHitFn (t_max = 0 for blocked rays), early exit.
using BvhAnyFn = void (*)(const AccelView& bvh, RayView rays);

struct AccelKernelTable {
    /// Packets of SIMD-width rays walk the tree together; a child is visited when any
    /// active lane hits its box.
    BvhClosestFn closest_packet;
    BvhAnyFn any_packet;
    /// One ray at a time; the 8 boxes of a node are tested in one SIMD operation (4 lanes
    /// twice on SSE).
    BvhClosestFn closest_single;
    BvhAnyFn any_single;
};

const AccelKernelTable& accel_kernel_table(Isa isa);

namespace isa_kernels {
const AccelKernelTable& sse2_accel();
const AccelKernelTable& sse42_accel();
const AccelKernelTable& avx2_accel();
const AccelKernelTable& avx512_accel();
}  // namespace isa_kernels

}  // namespace streamrt
