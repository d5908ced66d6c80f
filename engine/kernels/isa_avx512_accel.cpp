// The hierarchy traversal kernels built for avx512 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_avx512
#include "kernels/accel_kernel.h"

namespace streamrt::isa_kernels {

const AccelKernelTable& avx512_accel() {
    // Packets as wide as the level's float registers; node tests 8 lanes at once with AVX2 batches
    // (this file's copies of xsimd's AVX2 helpers are its own: kernels/isa_rename.cmake).
    static const AccelKernelTable table = isa_avx512::make_accel_table<xsimd::avx512bw, xsimd::fma3<xsimd::avx2>>();
    return table;
}

}  // namespace streamrt::isa_kernels
