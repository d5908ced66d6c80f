#pragma once
// What the hierarchy walks share about their stacks (mesh_kernel.h, accel_kernel.h).
// Included only by kernels/isa_*.cpp through intersect_kernel.h, inside their own namespace.
#include "simd/isa_namespace.h"

namespace streamrt::STREAMRT_ISA_NAMESPACE {

/// Pushes a node's met children, hits[0 .. nh) in the node's order, onto a walk's stack
/// farthest first, so that the nearest is popped first; equal entry distances keep the node's
/// order (an insertion sort on the entries' distance t).
template <class Entry>
inline void push_sorted(Entry* stack, int& sp, Entry* hits, int nh) {
    for (int a = 1; a < nh; ++a) {
        const Entry e = hits[a];
        int k = a;
        while (k > 0 && hits[k - 1].t < e.t) {
            hits[k] = hits[k - 1];
            --k;
        }
        hits[k] = e;
    }
    for (int k = 0; k < nh; ++k) stack[sp++] = hits[k];
}

}  // namespace streamrt::STREAMRT_ISA_NAMESPACE
