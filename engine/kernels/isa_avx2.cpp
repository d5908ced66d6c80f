// The kernels built for avx2 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_avx2
#include "kernels/intersect_kernel.h"

namespace streamrt::isa_kernels {

const KernelTable& avx2() {
    static const KernelTable table = isa_avx2::make_table<xsimd::fma3<xsimd::avx2>>(Isa::Avx2, "avx2");
    return table;
}

}  // namespace streamrt::isa_kernels
