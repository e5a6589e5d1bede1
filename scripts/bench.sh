#!/usr/bin/env bash
# Runs every benchmark against its peer and prints one table (bench/README.md).
# Installs the peers (NumPy/SciPy/pandas/matplotlib, Octave with its control and signal
# packages) when missing, builds Release into BUILD_DIR (default build/), then runs the CMake
# target `bench`. The table, CSV, JSON, Markdown and plot go to BUILD_DIR/bench/results.
#   scripts/bench.sh                  everything (a few minutes)
#   scripts/bench.sh ident            only the bench programs whose name contains "ident"
#   FLEXARM_BENCH_QUICK=1 scripts/bench.sh    fewer repeats (a smoke run)
#   FLEXARM_BENCH_CLOCK=cpu scripts/bench.sh  CPU time instead of wall time (busy machine)
# Not part of the tests: CI never runs it.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install-deps.sh"
bash "$here/scripts/install-deps.sh" --bench
build="${BUILD_DIR:-$here/build}"
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake "$build" -DFLEXARM_BENCH_FILTER="${1:-}" > /dev/null
cmake --build "$build" -j "${JOBS:-$(nproc)}" --target bench
