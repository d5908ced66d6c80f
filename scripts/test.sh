#!/usr/bin/env bash
# Second command of the README (and CI): install, build from scratch, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
ctest --test-dir build --output-on-failure -j2
