#!/usr/bin/env bash
# Installs every Debian package FlexArm needs to build, run and test.
# With --bench: the peers of the benchmarks instead (scripts/bench.sh; not needed by CI).
# Idempotent: packages already present are skipped, so a second run is quick.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  qt6-base-dev libqt6opengl6-dev libqt6svg6-dev libxkbcommon-dev
  libqcustomplot-dev libeigen3-dev libvtk9-dev
  libmatio-dev libfftw3-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xauth libgl1-mesa-dri
  poppler-utils python3-scipy zlib1g-dev libfast-float-dev
  clang libclang-rt-14-dev
  python3-h5py strace
  libsqlite3-dev slurm-wlm munge
)
# clang and libclang-rt-14-dev (its sanitizer and libFuzzer runtimes, only recommended by
# clang-14) build the AddressSanitizer/UBSan tests and the fuzz targets (scripts/sanitize.sh,
# scripts/fuzz.sh). python3-h5py writes the hostile v7.3 .mat files (scripts/make_hostile_data.py);
# strace lets the hostile-input tests see every file a run opens. libsqlite3-dev is the fleet's
# store; slurm-wlm and munge its cluster engine, which the tests run on a one-node Slurm they
# start themselves (tests/cli/slurm_fixture.sh).

if [ "${1:-}" = "--bench" ]; then
  PACKAGES=(python3-numpy python3-scipy python3-pandas python3-matplotlib
            octave octave-control octave-signal)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
