#!/usr/bin/env bash
# Installs what is missing, builds, and starts FlexArm on a bundled sample log.
# Without a display it runs the window under Xvfb once and saves a screenshot instead.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/install-deps.sh"
# Only the application: the tests are built by scripts/test.sh.
BUILD_TARGET=flexarm bash "$here/scripts/build.sh"
build="${BUILD_DIR:-$here/build}"
log="${1:-$here/sample_logs/three_mass_estimation_chirp.csv}"
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  exec "$build/app/flexarm" "$log"
fi
shot="$build/flexarm-window.png"
echo "run: no display; opening $log under Xvfb and saving a screenshot to $shot"
xvfb-run -a -s "-screen 0 1600x1000x24" "$build/app/flexarm" --screenshot "$shot" "$log"
echo "run: wrote $shot"
