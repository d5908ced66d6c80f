#!/usr/bin/env bash
# Second command of the README (and the first step of CI): install the dependencies, build
# from scratch (Release) and run the whole test suite with ctest: 7 min 55 s on a fresh clone
# on 2 free cores (AMD EPYC, AVX2) with the packages already installed (2026-12-02; 370 tests,
# ctest 91 s of it; 3 min 52 s and 311 tests on 2026-11-28, before degree 6's shade kernels and
# pipelines); most of it is the build. The slow checks
# (the parser fuzzer, the ASan+UBSan build and its suite) are run after it by .ci/run, or by
# hand: scripts/fuzz.sh 60, JOBS=2 scripts/sanitize.sh asan.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
# --no-tests=error: a build configured without the tests (STREAMRT_BUILD_TESTS=OFF, or a
# broken tests/CMakeLists.txt) has none to run, and ctest would report that as success.
ctest --test-dir build --output-on-failure --no-tests=error -j2
