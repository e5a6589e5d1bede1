#!/usr/bin/env bash
# Configures and builds FlexArm (Release) into BUILD_DIR (default: build/ in the repository).
# BUILD_TARGET=flexarm builds only the application (what scripts/run.sh needs), not the tests.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$here/build}"
jobs="${JOBS:-$(nproc)}"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build "$build" -j "$jobs" ${BUILD_TARGET:+--target "$BUILD_TARGET"}
