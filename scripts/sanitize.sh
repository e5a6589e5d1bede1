#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build (clang) of the core, the command line,
# their tests and the fuzz targets (no GUI), then every core and command-line test under it at
# reduced sizes (FLEXARM_TEST_REDUCED=1 shrinks the slow ones), the threaded tests repeated,
# and a short fuzzing run. scripts/test.sh runs this after the Release tests.
#
#   bash scripts/sanitize.sh [--configure-only DIR]
#
# Environment: SANITIZE_BUILD_DIR (default build-asan/), FUZZ_SECONDS per fuzz target
# (default 20; 0 skips fuzzing), JOBS.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SANITIZE_BUILD_DIR:-$here/build-asan}"
configure_only=0
if [ "${1:-}" = "--configure-only" ]; then
  configure_only=1
  build="$2"
fi
jobs="${JOBS:-$(nproc)}"

flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
flags="$flags -O1 -g1"  # (the readers also get -fsanitize=fuzzer-no-link: core/CMakeLists.txt)
launcher=()
if command -v ccache > /dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache); fi
cmake -S "$here" -B "$build" -G Ninja "${launcher[@]}" \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=None \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DFLEXARM_BUILD_GUI=OFF -DBUILD_TESTING=ON -DFLEXARM_FUZZ=ON > /dev/null
[ "$configure_only" = 1 ] && exit 0

cmake --build "$build" -j "$jobs"

# Leaks are errors; a failed check stops the test with a stack.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$here/tests/sanitizer/lsan.supp"
export FLEXARM_TEST_REDUCED=1
export XDG_CONFIG_HOME="$build/test-config"
ctest --test-dir "$build" --output-on-failure -j "$jobs" --timeout 900
# The tests that run threads (FFT planning, the split CSV parse, discovery's parallel
# candidates, replays) again, several times, where a race has the best chance to show.
ctest --test-dir "$build" --output-on-failure -j "$jobs" --timeout 900 \
  -R "$(paste -sd '|' "$here/tests/threaded_tests.txt")" --repeat until-fail:2

seconds="${FUZZ_SECONDS:-20}"
if [ "$seconds" != 0 ]; then
  # A fixed seed: the short run in the test command repeats the same inputs from run to run,
  # so it fails for a change, not for the draw; longer runs (scripts/fuzz.sh) draw their own.
  BUILD_DIR="$build" FUZZ_DIR="$build/fuzzing" bash "$here/scripts/fuzz.sh" --seconds "$seconds" \
    --seed "${FUZZ_SEED:-1}"
fi
