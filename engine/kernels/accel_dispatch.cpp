#include "kernels/accel_kernel_table.h"

namespace streamrt {

const AccelKernelTable& accel_kernel_table(Isa isa) {
    switch (isa) {
        case Isa::Sse42: return isa_kernels::sse42_accel();
        case Isa::Avx2: return isa_kernels::avx2_accel();
        case Isa::Avx512: return isa_kernels::avx512_accel();
        case Isa::Sse2: break;
    }
    return isa_kernels::sse2_accel();
}

}  // namespace streamrt
