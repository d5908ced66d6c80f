// The arithmetic-limit loop (perf/arith_limit.inc) built for avx2.
#define ARITH_NS avx2
#define ARITH_ARCH xsimd::fma3<xsimd::avx2>
#include "arith_limit.inc"
