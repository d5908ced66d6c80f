#pragma once
// The arithmetic-limit loops of perf/arith_limit.inc, one per x86-64 level.
#include <cstdint>

namespace perf {

struct MixRunner {
    float (*run)(std::int64_t tests, int n_fma, int n_div, int n_sqrt);
    int lanes;
};

namespace sse2 { extern const MixRunner runner; }
namespace sse42 { extern const MixRunner runner; }
namespace avx2 { extern const MixRunner runner; }
namespace avx512 { extern const MixRunner runner; }

/// The sphere kernel's floating-point operations per ray-object test (one lane), counted
/// from kernels/intersect_kernel.h and shapes/sphere_math.h + quadratic.h:
///   to_canonical 18 (9 FMA origin, 6 FMA + 3 mul direction); dot(d,d), dot(o,d) 5 each,
///   dot(o,o) - 1 6; perp = o + d t_mid 6; dot(perp,perp) 5; a (1 - |perp|^2) 2;
///   sign(b) root and b + ... 2  -> 49 add/mul/FMA; -b/a, q/a, c/q -> 3 div; 1 sqrt.
inline constexpr int kSphereFma = 49, kSphereDiv = 3, kSphereSqrt = 1;

}  // namespace perf
