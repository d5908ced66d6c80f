#!/usr/bin/env bash
# Builds the test suite with sanitizers and runs it with ctest.
#   scripts/sanitize.sh asan [ctest args]      AddressSanitizer + UndefinedBehaviorSanitizer
#                                               into build-asan/, every test
#   scripts/sanitize.sh tsan [ctest args]      ThreadSanitizer into build-tsan/, against a
#                                               oneTBB built with -fsanitize=thread from
#                                               Debian's source package (below), every test
#                                               but two that TSan cannot pass (below);
#                                               the threaded ones alone (quicker):
#                                               -R "render threads|cli:|bit-identical|BVH"
#   scripts/sanitize.sh tsan-std [ctest args]  fallback for a machine that cannot fetch the
#                                               source package: ThreadSanitizer into
#                                               build-tsan-std/ with the loops on std::thread
#                                               instead of oneTBB (STREAMRT_STD_THREADS in
#                                               engine/parallel/parallelism.h)
# RelWithDebInfo: the top-level CMakeLists.txt sets its flags (with a sanitizer -O1 -DNDEBUG
# and -g1: line tables, enough for file:line in reports; -O1 as the sanitizers' documentation
# advises, and the build takes a third of its -O3 time); the perf targets and the Python
# module are not configured, and only streamrt_tests and streamrt are built (below).
# JOBS (default 1) sets the build parallelism: sanitizer builds need much memory per job.
set -euo pipefail
cd "$(dirname "$0")/.."
kind=${1:-asan}
shift || true
jobs=${JOBS:-1}
extra=()
case "$kind" in
  asan)
    dir=build-asan
    sanitize="address,undefined"
    export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
    export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
    # The test drivers' subprocess time-outs only catch hangs; instrumented code runs several
    # times slower, so they are multiplied (tests/distributed/check_distributed.py).
    export STREAMRT_TEST_TIMEOUT_SCALE=10
    # The SIMD shade kernels' pictures at every level take ~165 s each under ASan and run no
    # kernel that the stream engine tests "... the SIMD path on every scene, every ISA" and
    # "hits regrouped by material and kind (gathered) ..., every ISA" do not; without them the
    # sanitized suite finishes within CI's budget. The same holds for their degree-6 run
    # (3.7 s in Release, so about 170 s under ASan at the ratio above): the doctest case
    # "degree 6: the picture is the same for every thread count and ISA level" runs those
    # kernels sanitized (at sse2 and the best level). gi_against_embree (10 s in Release,
    # about 7 minutes instrumented) is a statistical comparison with Embree's uninstrumented
    # path tracer; the degree-6 doctest cases run its code paths under the sanitizers.
    # (Release times: 2026-12-02, 2 cores.)
    filter=(-E "isa_pictures_simd_shade$|isa_pictures_simd_shade_gathered|isa_pictures_simd_shade_degree6$|gi_against_embree")
    ;;
  tsan|tsan-std)
    dir=build-$kind
    sanitize="thread"
    # (engine/image/display.cpp builds its one target_clones function without clones under TSan:
    # GCC instruments the clones' load-time resolver, which runs before the TSan runtime.)
    extra=()
    # Suppressions (each with its reason) live in tests/tsan.supp.
    export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/tests/tsan.supp"
    export STREAMRT_TEST_TIMEOUT_SCALE=20  # hang catchers only, as for asan
    # One test cannot pass under TSan, for a reason that is not a race: it bounds the peak
    # RSS (TSan's shadow memory adds ~12 MB).
    filter=(-E "peak memory at depth 16 and 32")
    ;;
  *) echo "usage: scripts/sanitize.sh asan|tsan|tsan-std [ctest args]" >&2; exit 2 ;;
esac
start=$(date +%s)

if [[ $kind == tsan ]]; then
  # Debian's libtbb.so.12 is not instrumented: TSan would not see the happens-before edges
  # oneTBB makes when it hands a task to a worker and joins it. So build the same oneTBB
  # (the version of the installed libtbb-dev, from Debian's source package with Debian's
  # patches) with -fsanitize=thread, the library only, into $dir/tbb-install, and build the
  # tests against it. The source is fetched here, into $dir, never kept in the repository;
  # apt runs on a private list folder (no change to the machine's apt sources). Needs
  # dpkg-dev (dpkg-source) and access to Debian's package archive; done once per version.
  tbb_version=$(dpkg-query -W -f='${Version}' libtbb-dev)
  tbb_prefix=$PWD/$dir/tbb-install
  if [[ ! -f $tbb_prefix/.version || $(cat "$tbb_prefix/.version") != "$tbb_version" ]]; then
    apt_dir=$PWD/$dir/apt
    rm -rf "$apt_dir" "$dir/onetbb-src" "$dir/onetbb-build" "$tbb_prefix"
    mkdir -p "$apt_dir/sources.list.d" "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial" \
      "$dir/onetbb-src"
    cat >"$apt_dir/sources.list.d/debian-src.sources" <<SOURCES
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb-src
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SOURCES
    apt_opts=(-qq -o Dir::Etc::SourceList=/dev/null -o Dir::Etc::SourceParts="$apt_dir/sources.list.d"
              -o Dir::State::Lists="$apt_dir/lists" -o Dir::Cache="$apt_dir/cache"
              -o Debug::NoLocking=1 -o APT::Sandbox::User=root)
    # --no-check as apt-get source itself does: apt checked every file against the signed index.
    apt-get "${apt_opts[@]}" update && (cd "$dir/onetbb-src" \
      && apt-get "${apt_opts[@]}" source --download-only "onetbb=$tbb_version" \
      && dpkg-source --no-check -x ./*.dsc tree >/dev/null) || {
      echo "sanitize.sh: could not fetch Debian's onetbb $tbb_version source package; without" \
        "it, scripts/sanitize.sh tsan-std checks the loops on std::thread instead" >&2
      exit 1
    }
    # TBB_SANITIZE=thread is oneTBB's own option for a TSan build (its -fsanitize=thread also
    # turns on oneTBB's sanitizer mode, __TBB_USE_THREAD_SANITIZER). The project's compiler
    # (the same libtsan). No tests, examples, Python, tbbmalloc or hwloc binding: streamrt
    # links TBB::tbb alone.
    cmake -S "$dir/onetbb-src/tree" -B "$dir/onetbb-build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DTBB_SANITIZE=thread -DTBB_TEST=OFF \
      -DTBB_EXAMPLES=OFF -DTBB4PY_BUILD=OFF -DTBBMALLOC_BUILD=OFF -DTBB_STRICT=OFF \
      -DTBB_DISABLE_HWLOC_AUTOMATIC_SEARCH=ON -DCMAKE_INSTALL_PREFIX="$tbb_prefix" >/dev/null
    # Its compiler warnings go to a log; shown when the build fails.
    echo "sanitize.sh: building oneTBB $tbb_version with -fsanitize=thread ($dir/onetbb-build.log)"
    ninja -C "$dir/onetbb-build" -j"$jobs" >"$dir/onetbb-build.log" 2>&1 \
      || { tail -n 40 "$dir/onetbb-build.log" >&2; exit 1; }
    cmake --install "$dir/onetbb-build" >/dev/null
    echo "$tbb_version" >"$tbb_prefix/.version"
  fi
  extra+=(-DTBB_DIR="$tbb_prefix/lib/cmake/TBB")
elif [[ $kind == tsan-std ]]; then
  extra=(-DCMAKE_CXX_FLAGS="-DSTREAMRT_STD_THREADS=1")
fi
tbb_built=$(date +%s)

# Without MPI: Open MPI's own allocations would read as leaks, and this also checks that the
# project builds and passes without it (the shard and checkpoint tests still run). Without the
# Python module: an instrumented module cannot be loaded into an uninstrumented interpreter.
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSTREAMRT_SANITIZE="$sanitize" \
  -DSTREAMRT_MPI=OFF -DSTREAMRT_BUILD_PERF=OFF -DSTREAMRT_BUILD_PYTHON=OFF \
  -DSTREAMRT_TEST_TIMEOUT_SCALE=10 \
  "${extra[@]}" >/dev/null
# Only what ctest runs: the test binary and the program (the CLI, reference and distributed
# tests run it); the engine library and the modules it loads come with them. Nothing else
# that a configure may add (examples, tools) is compiled with the sanitizers for nothing.
ninja -C "$dir" -j"$jobs" streamrt_tests streamrt
if [[ $kind == tsan ]]; then
  # The test binary and the streamrt binary (the cli tests) must load the instrumented
  # library, not /usr/lib's.
  for exe in "$dir/tests/streamrt_tests" "$dir/engine/streamrt"; do
    libs=$(ldd "$exe")  # not piped into grep -q: with pipefail, ldd's SIGPIPE fails the test
    if [[ $libs != *"libtbb.so.12 => $tbb_prefix/lib/libtbb.so.12 "* ]]; then
      echo "sanitize.sh: $exe does not load $tbb_prefix/lib/libtbb.so.12" >&2
      grep tbb <<<"$libs" >&2
      exit 1
    fi
  done
fi
built=$(date +%s)
# --no-tests=error: a filter or a configure that leaves nothing to run is not a clean run.
ctest --test-dir "$dir" --output-on-failure --no-tests=error -j2 "${filter[@]}" "$@"
done_at=$(date +%s)
if [[ $kind == tsan ]]; then
  echo "sanitize.sh $kind: oneTBB $((tbb_built - start)) s, build $((built - tbb_built)) s, tests $((done_at - built)) s"
else
  echo "sanitize.sh $kind: build $((built - start)) s, tests $((done_at - built)) s"
fi
