// The hierarchy traversal kernels built for avx2 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_avx2
#include "kernels/accel_kernel.h"

namespace streamrt::isa_kernels {

const AccelKernelTable& avx2_accel() {
    // Packets as wide as the level's float registers; node tests 8 lanes at once.
    static const AccelKernelTable table = isa_avx2::make_accel_table<xsimd::fma3<xsimd::avx2>, xsimd::fma3<xsimd::avx2>>();
    return table;
}

}  // namespace streamrt::isa_kernels
