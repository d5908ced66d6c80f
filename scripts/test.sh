#!/usr/bin/env bash
# Second command of the README (and the first step of CI): install the dependencies, build
# from scratch (Release) and run the whole test suite with ctest: 3 min 52 s on a fresh clone
# on 2 free cores with the packages already installed (2026-11-28; 311 tests, ctest 37 s of it),
# up to 12 minutes when other work loads the machine; most of it is the build. The slow checks
# (the parser fuzzer, the ASan+UBSan build and its suite) are run after it by .ci/run, or by
# hand: scripts/fuzz.sh 60, JOBS=2 scripts/sanitize.sh asan.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
# --no-tests=error: a build configured without the tests (STREAMRT_BUILD_TESTS=OFF, or a
# broken tests/CMakeLists.txt) has none to run, and ctest would report that as success.
ctest --test-dir build --output-on-failure --no-tests=error -j2
