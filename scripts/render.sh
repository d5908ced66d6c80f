#!/usr/bin/env bash
# First command of the README: install, build, render the default scene to whitted.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
build/engine/streamrt -j2 scenes/whitted.cfg -o whitted.png
