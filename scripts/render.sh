#!/usr/bin/env bash
# First command of the README: install, build the streamrt command alone (not the tests, the
# benchmarks or the Python module, which a first picture does not need; scripts/test.sh builds
# everything), render the default scene to whitted.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --target streamrt
build/engine/streamrt -j2 scenes/whitted.cfg -o whitted.png
