#pragma once
// Helpers of the lane tests (tests/simd, tests/render/texture_lanes_test.cpp): a float's
// bits, for bit-for-bit comparisons of batch lanes with scalars, and a small deterministic
// generator of test inputs.
#include <cstdint>
#include <cstring>

namespace streamrt::test {

inline std::uint32_t float_bits(float f) {
    std::uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
}

/// A 64-bit linear congruential generator (no global state, the same numbers every run).
struct Lcg {
    std::uint64_t x = 0x9e3779b97f4a7c15ull;
    double next() {  // in [0, 1)
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        return double(x >> 11) * (1.0 / 9007199254740992.0);
    }
};

}  // namespace streamrt::test
