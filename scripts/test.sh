#!/usr/bin/env bash
# Second command of the README (and the first step of CI): install the dependencies, build
# from scratch (Release) and run the whole test suite with ctest: 10 to 12 minutes on a
# 2-core machine with the packages already installed, most of it the build. The slow checks
# (the parser fuzzer, the ASan+UBSan build and its suite) are run after it by .ci/run, or by
# hand: scripts/fuzz.sh 60, JOBS=2 scripts/sanitize.sh asan.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j2
