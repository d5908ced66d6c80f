// Degenerate rays (zero, denormal, huge, infinite, NaN components) through every kernel:
// a definite answer and no more than twice the cost of ordinary rays (docs/stability.md).
#include <doctest/doctest.h>

#include "../../perf/bad_rays_probe.h"

using namespace streamrt;

TEST_CASE("stress: degenerate rays get a definite answer from every kernel at every ISA, at most 2x the cost") {
    const std::size_t n = 1 << 13;
    probe::Rays normal = probe::make_rays(n, false), bad = probe::make_rays(n, true);
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const std::string name = isa_name(isa);
        CAPTURE(name);
        const probe::Result a = probe::run(kernel_table(isa), normal, 3);
        const probe::Result b = probe::run(kernel_table(isa), bad, 3);
        CHECK(a.bad_answers == 0);
        CHECK(b.bad_answers == 0);
        MESSAGE(name << ": degenerate / ordinary time " << b.seconds / a.seconds);
        CHECK(b.seconds <= 2.0 * a.seconds);
    }
}
