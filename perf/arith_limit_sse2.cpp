// The arithmetic-limit loop (perf/arith_limit.inc) built for sse2.
#define ARITH_NS sse2
#define ARITH_ARCH xsimd::sse2
#include "arith_limit.inc"
