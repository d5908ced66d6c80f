#!/usr/bin/env bash
# Second command of the README (and CI): install, build from scratch, run every test, fuzz the
# scene parser for 60 s, then run the tests again under ASan + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j2
# The scene-parser fuzz target (clang + libFuzzer, ~25 s of compile CPU time) for 60 s;
# SKIP_FUZZ=1 skips it.
if [[ ${SKIP_FUZZ:-0} != 1 ]]; then
  scripts/fuzz.sh 60
fi
# The same suite built with AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/;
# docs/robustness.md has the time it takes). SKIP_SANITIZE=1 skips it.
if [[ ${SKIP_SANITIZE:-0} != 1 ]]; then
  JOBS=${JOBS:-2} scripts/sanitize.sh asan
fi
