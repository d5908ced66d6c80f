// Degenerate rays through every kernel (perf/bad_rays_probe.h): definite answers and cost
// against ordinary rays, every supported ISA level. `--json` prints the best level's figures
// for scripts/stability_report.py.
#include <cstdio>
#include <cstring>

#include "bad_rays_probe.h"

using namespace streamrt;

int main(int argc, char** argv) {
    const bool json = argc > 1 && std::strcmp(argv[1], "--json") == 0;
    const std::size_t n = 1 << 15;
    probe::Rays normal = probe::make_rays(n, false), bad = probe::make_rays(n, true);
    std::size_t non_definite = 0;
    double ns_normal = 0, ns_bad = 0;
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const probe::Result a = probe::run(kernel_table(isa), normal, 5);
        const probe::Result b = probe::run(kernel_table(isa), bad, 5);
        non_definite += a.bad_answers + b.bad_answers;
        const double per = 1e9 / double(n) / (2.0 * kShapeKindCount);
        if (!json)
            std::printf("%-7s normal %.1f ns/ray/kernel, degenerate %.1f (x%.2f), non-definite answers %zu\n",
                        isa_name(isa), a.seconds * per, b.seconds * per, b.seconds / a.seconds,
                        a.bad_answers + b.bad_answers);
        if (isa == best_isa()) ns_normal = a.seconds * per, ns_bad = b.seconds * per;
    }
    if (json)
        std::printf("{\"what\": \"rays with zero, denormal, huge, infinite or NaN components through every kernel "
                    "(closest and any hit, 6 shapes x 6 objects, every ISA level, %zu rays)\", \"non_finite\": %zu, "
                    "\"ns_normal\": %.3f, \"ns_bad\": %.3f, \"ratio\": %.3f}\n",
                    n, non_definite, ns_normal, ns_bad, ns_bad / ns_normal);
    return non_definite == 0 ? 0 : 1;
}
