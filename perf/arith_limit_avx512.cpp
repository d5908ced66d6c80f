// The arithmetic-limit loop (perf/arith_limit.inc) built for avx512.
#define ARITH_NS avx512
#define ARITH_ARCH xsimd::avx512bw
#include "arith_limit.inc"
