#include "kernels/kernel_table.h"

#include <xsimd/xsimd.hpp>

namespace streamrt {

bool isa_supported(Isa isa) {
    const auto a = xsimd::available_architectures();
    switch (isa) {
        case Isa::Sse2: return true;  // every x86-64 CPU
        case Isa::Sse42: return a.sse4_2;
        case Isa::Avx2: return a.fma3_avx2;
        case Isa::Avx512: return a.avx512bw && a.avx512dq && a.avx512cd && a.avx512f;
    }
    return false;
}

Isa best_isa() {
    for (Isa isa : {Isa::Avx512, Isa::Avx2, Isa::Sse42})
        if (isa_supported(isa)) return isa;
    return Isa::Sse2;
}

const char* isa_name(Isa isa) { return name_of(kIsaNames, isa).data(); }  // the literals end in NUL

bool parse_isa(const std::string& s, Isa& out) {
    const auto isa = value_named(kIsaNames, s);
    if (isa) out = *isa;
    return isa.has_value();
}

const KernelTable& kernel_table(Isa isa) {
    switch (isa) {
        case Isa::Sse42: return isa_kernels::sse42();
        case Isa::Avx2: return isa_kernels::avx2();
        case Isa::Avx512: return isa_kernels::avx512();
        case Isa::Sse2: break;
    }
    return isa_kernels::sse2();
}

}  // namespace streamrt
