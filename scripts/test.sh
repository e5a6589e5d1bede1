#!/usr/bin/env bash
# Installs what is missing, builds FlexArm with its tests, and runs every test.
# GUI tests need an X display: without one (or under CI=true) ctest runs under Xvfb.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install-deps.sh"
export BUILD_DIR="${BUILD_DIR:-$here/build}"
bash "$here/scripts/build.sh" -DBUILD_TESTING=ON
export XDG_CONFIG_HOME="$BUILD_DIR/test-config"   # tests never touch the user's settings
ctest_cmd=(ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)" --timeout 900)
if [ "${CI:-}" = "true" ] || [ -z "${DISPLAY:-}" ]; then
  xvfb-run -a -s "-screen 0 1600x1200x24" "${ctest_cmd[@]}"
else
  "${ctest_cmd[@]}"
fi
