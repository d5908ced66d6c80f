#!/usr/bin/env bash
# Builds the test suite with sanitizers and runs it with ctest.
#   scripts/sanitize.sh asan [ctest args]   AddressSanitizer + UndefinedBehaviorSanitizer
#                                            into build-asan/, every test
#   scripts/sanitize.sh tsan [ctest args]   ThreadSanitizer into build-tsan/, the tests that
#                                            run threads (renders, the command line, the
#                                            parallel BVH build); loops run on std::thread
#                                            there (engine/parallel/parallelism.h)
# Debug-ish flags (-O1 -g) keep the build quick on 2 cores; the perf targets are not built.
# JOBS (default 1) sets the build parallelism: sanitizer builds need much memory per job.
set -euo pipefail
cd "$(dirname "$0")/.."
kind=${1:-asan}
shift || true
jobs=${JOBS:-1}
case "$kind" in
  asan)
    dir=build-asan
    sanitize="address,undefined"
    export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
    export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
    filter=()
    ;;
  tsan)
    dir=build-tsan
    sanitize="thread"
    # Suppressions (each with its reason) live in tests/tsan.supp.
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/tests/tsan.supp"
    filter=(-R "render threads|cli:|bit-identical|BVH")
    ;;
  *) echo "usage: scripts/sanitize.sh asan|tsan [ctest args]" >&2; exit 2 ;;
esac
start=$(date +%s)
# Without MPI: Open MPI's own allocations would read as leaks, and this also checks that the
# project builds and passes without it (the shard and checkpoint tests still run).
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSTREAMRT_SANITIZE="$sanitize" \
  -DSTREAMRT_MPI=OFF -DSTREAMRT_BUILD_PERF=OFF -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g -fno-math-errno" >/dev/null
ninja -C "$dir" -j"$jobs"
built=$(date +%s)
ctest --test-dir "$dir" --output-on-failure -j2 "${filter[@]}" "$@"
done_at=$(date +%s)
echo "sanitize.sh $kind: build $((built - start)) s, tests $((done_at - built)) s"
