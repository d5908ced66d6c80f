// The kernels built for avx512 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_avx512
#include "kernels/intersect_kernel.h"

namespace streamrt::isa_kernels {

const KernelTable& avx512() {
    static const KernelTable table = isa_avx512::make_table<xsimd::avx512bw>(Isa::Avx512, "avx512");
    return table;
}

}  // namespace streamrt::isa_kernels
