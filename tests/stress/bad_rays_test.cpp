// Degenerate rays (zero, denormal, huge, infinite, NaN components) through every kernel get a
// definite answer (docs/stability.md). No time is asserted here: the suite has no timed tests.
// The cost of degenerate against ordinary rays (docs/stability.md: at most 2x) is measured by
// the benchmark perf/bad_rays.cpp (`build/perf/bad_rays`), which shares perf/bad_rays_probe.h.
#include <doctest/doctest.h>

#include "../../perf/bad_rays_probe.h"

using namespace streamrt;

TEST_CASE("stress: degenerate rays get a definite answer from every kernel at every ISA") {
    const std::size_t n = 1 << 13;
    probe::Rays normal = probe::make_rays(n, false), bad = probe::make_rays(n, true);
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const std::string name = isa_name(isa);
        CAPTURE(name);
        const probe::Result a = probe::run(kernel_table(isa), normal, 1);
        const probe::Result b = probe::run(kernel_table(isa), bad, 1);
        CHECK(a.rays > 0);
        CHECK(b.rays > 0);
        CHECK(a.bad_answers == 0);
        CHECK(b.bad_answers == 0);
    }
}
