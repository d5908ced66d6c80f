// The arithmetic-limit loop (perf/arith_limit.inc) built for sse42.
#define ARITH_NS sse42
#define ARITH_ARCH xsimd::sse4_2
#include "arith_limit.inc"
