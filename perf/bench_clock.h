#pragma once
// The timing programs' clock (perf/). Not a test.
#include <chrono>

namespace streamrt::perf {

/// Seconds on the steady clock.
inline double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace streamrt::perf
