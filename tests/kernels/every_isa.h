#pragma once
// The kernel tests' loop over instruction sets: every level this machine runs.
#include <doctest/doctest.h>

#include "kernels/kernel_table.h"

namespace streamrt {

/// Calls run(isa) for every ISA level this machine supports, the level's name captured for
/// the messages of the checks run() makes.
template <class Run>
void at_every_isa(Run&& run) {
    for (int level = 0; level < kIsaCount; ++level) {
        const Isa isa = Isa(level);
        if (!isa_supported(isa)) continue;
        CAPTURE(isa_name(isa));
        run(isa);
    }
}

}  // namespace streamrt
