#!/usr/bin/env bash
# Builds the scene-parser fuzz target (tests/fuzz/scene_fuzz.cpp) with clang++ and libFuzzer
# (+ AddressSanitizer + UndefinedBehaviorSanitizer) into build-fuzz/ and runs it for SECONDS
# (default 60) in one process on one core, from a corpus seeded with scenes/. Crashing inputs land in
# build-fuzz/artifacts/; keep each as tests/fuzz/regressions/<name>.cfg once fixed.
# Usage: scripts/fuzz.sh [SECONDS] [extra libFuzzer flags...]
#        scripts/fuzz.sh ply [SECONDS] [flags...]: the PLY reader alone on raw bytes
#        (tests/fuzz/ply_fuzz.cpp, seeds tests/fuzz/ply_corpus), into build-fuzz/ply_fuzz.
#        scripts/fuzz.sh obj [SECONDS] [flags...]: the OBJ reader alone, the same way
#        (tests/fuzz/obj_fuzz.cpp, seeds tests/fuzz/obj_corpus), into build-fuzz/obj_fuzz.
set -euo pipefail
cd "$(dirname "$0")/.."
target=scene
[[ ${1:-} == ply || ${1:-} == obj ]] && target=$1 && shift
seconds=${1:-60}
shift || true
CXX=${FUZZ_CXX:-clang++-14}
command -v "$CXX" >/dev/null || CXX=clang++
out=build-fuzz
if [[ $target == ply || $target == obj ]]; then
  mkdir -p "$out/${target}_corpus" "$out/artifacts"
  bin="$out/${target}_fuzz"
  reader_sources=(tests/fuzz/${target}_fuzz.cpp engine/core/*.cpp engine/accel/*.cpp engine/mesh/*.cpp)
  rebuild=0
  [[ -x $bin ]] || rebuild=1
  for s in "${reader_sources[@]}" engine/{core,parallel,accel,mesh}/*.h; do [[ $s -nt $bin ]] && rebuild=1; done
  if ((rebuild)); then
    echo "fuzz.sh: building $bin with $CXX"
    "$CXX" -std=c++20 -O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer,address,undefined \
      -fno-sanitize-recover=undefined -Iengine "${reader_sources[@]}" -ltinyobjloader -ltbb -lz -o "$bin"
  fi
  cp -n tests/fuzz/${target}_corpus/* "$out/${target}_corpus/" 2>/dev/null || true
  exec "$bin" "$out/${target}_corpus" -max_total_time="$seconds" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
    -malloc_limit_mb=64 -print_final_stats=1 -artifact_prefix="$out/artifacts/${target}-" "$@"
fi
mkdir -p "$out/corpus" "$out/artifacts"
# The scene reader and everything it may call: the layers up to scene/ (docs/architecture.md; the
# architecture_layers test keeps their includes from climbing), the image writers that the memory
# estimate asks for a buffer size (engine/driver/limits.cpp), tinyobjloader, stb, zlib, OpenEXR and
# TBB. Globbed by folder, so a new source file in those layers is built here without a list to keep.
shopt -s nullglob
sources=(tests/fuzz/scene_fuzz.cpp engine/{core,parallel,shapes,accel,mesh,scene,image}/*.cpp engine/driver/limits.cpp)
bin="$out/scene_fuzz"
# Rebuild when a source is newer than the binary.
rebuild=0
[[ -x $bin ]] || rebuild=1
for s in "${sources[@]}" engine/scene/*.h engine/core/*.h engine/driver/limits.h engine/mesh/*.h \
         engine/accel/*.h engine/image/*.h engine/parallel/*.h tests/fuzz/*.h; do
  [[ $s -nt $bin ]] && rebuild=1
done
if ((rebuild)); then
  echo "fuzz.sh: building $bin with $CXX"
  "$CXX" -std=c++20 -O1 -g -fno-omit-frame-pointer \
    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
    -Iengine -Itests -I/usr/include/stb $(pkg-config --cflags OpenEXR) "${sources[@]}" \
    -ltinyobjloader -ltbb -lz $(pkg-config --libs OpenEXR) -o "$bin"
fi
# Seed corpus: every example scene, the fuzz seeds (tests/fuzz/corpus: mesh statements on the
# include tree's tri.obj) and the regression inputs.
cp -n scenes/*.cfg scenes/degrees/*.cfg scenes/anim/*.cfg tests/fuzz/corpus/*.cfg "$out/corpus/" 2>/dev/null || true
for f in tests/fuzz/regressions/*; do [[ -f $f ]] && cp -n "$f" "$out/corpus/"; done
echo "fuzz.sh: running for ${seconds}s (corpus $(ls "$out/corpus" | wc -l) files)"
exec "$bin" "$out/corpus" -dict=tests/fuzz/scene.dict -max_total_time="$seconds" \
  -max_len=4096 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$out/artifacts/" "$@"
