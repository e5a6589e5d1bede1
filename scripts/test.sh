#!/usr/bin/env bash
# Installs what is missing, builds FlexArm with its tests, and runs every test; then the
# sanitizer build runs the core and command-line tests again and fuzzes briefly.
# GUI tests need an X display: without one (or under CI=true) ctest runs under Xvfb.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install-deps.sh"
export BUILD_DIR="${BUILD_DIR:-$here/build}"
bash "$here/scripts/build.sh" -DBUILD_TESTING=ON
export XDG_CONFIG_HOME="$BUILD_DIR/test-config"   # tests never touch the user's settings
ctest_cmd=(ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$(nproc)" --timeout 900)
# The tests that run threads, twice more at reduced sizes: a race gets more chances to show.
threaded=(-R "$(paste -sd '|' "$here/tests/threaded_tests.txt")" --repeat until-fail:2)
if [ "${CI:-}" = "true" ] || [ -z "${DISPLAY:-}" ]; then
  xvfb-run -a -s "-screen 0 1600x1200x24" "${ctest_cmd[@]}"
  FLEXARM_TEST_REDUCED=1 xvfb-run -a -s "-screen 0 1600x1200x24" "${ctest_cmd[@]}" "${threaded[@]}"
else
  "${ctest_cmd[@]}"
  FLEXARM_TEST_REDUCED=1 "${ctest_cmd[@]}" "${threaded[@]}"
fi
# AddressSanitizer + UBSan build of the core, the command line and their tests at reduced
# sizes, and a short fuzzing run (FLEXARM_SANITIZE=0 skips it, e.g. for a quick local run).
if [ "${FLEXARM_SANITIZE:-1}" != 0 ]; then
  bash "$here/scripts/sanitize.sh"
fi
