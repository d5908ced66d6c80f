// The kernels built for sse4.2 (flags in kernels/isa_flags.cmake).
#define STREAMRT_ISA_NAMESPACE isa_sse42
#include "kernels/intersect_kernel.h"

namespace streamrt::isa_kernels {

const KernelTable& sse42() {
    static const KernelTable table = isa_sse42::make_table<xsimd::sse4_2>(Isa::Sse42, "sse4.2");
    return table;
}

}  // namespace streamrt::isa_kernels
