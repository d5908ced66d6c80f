// The hierarchy traversal kernels built for sse2 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_sse2
#include "kernels/accel_kernel.h"

namespace streamrt::isa_kernels {

const AccelKernelTable& sse2_accel() {
    // Packets as wide as the level's float registers; node tests 4 lanes at a time.
    static const AccelKernelTable table = isa_sse2::make_accel_table<xsimd::sse2, xsimd::sse2>();
    return table;
}

}  // namespace streamrt::isa_kernels
