// The kernels built for sse2 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_sse2
#include "kernels/intersect_kernel.h"

namespace streamrt::isa_kernels {

const KernelTable& sse2() {
    static const KernelTable table = isa_sse2::make_table<xsimd::sse2>(Isa::Sse2, "sse2");
    return table;
}

}  // namespace streamrt::isa_kernels
