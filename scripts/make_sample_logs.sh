#!/usr/bin/env bash
# Regenerates sample_logs/ with the FlexArm simulator (flexarm simulate).
#   scripts/make_sample_logs.sh [FLEXARM] [DIR]          write the logs into DIR
#   scripts/make_sample_logs.sh --check FLEXARM DIR      regenerate into a temporary
#       directory and compare every file byte for byte with DIR (exit 1 on a difference)
# FLEXARM defaults to build/app/flexarm, DIR to sample_logs/ next to this script's folder.
set -euo pipefail

check=0
if [[ "${1:-}" == "--check" ]]; then
  check=1
  shift
fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
flexarm="${1:-$here/build/app/flexarm}"
target="${2:-$here/sample_logs}"
if [[ ! -x "$flexarm" ]]; then
  echo "make_sample_logs.sh: no flexarm executable at $flexarm" >&2
  exit 2
fi

if [[ $check -eq 1 ]]; then
  out="$(mktemp -d)"
  trap 'rm -rf "$out"' EXIT
else
  out="$target"
  mkdir -p "$out"
fi

sim() {  # sim NAME ARGS...
  local name="$1"
  shift
  "$flexarm" simulate "$@" --out "$out/$name.csv" > /dev/null
}

# Chapter 5: three-mass arm (Table 5.7 p6) at the controller rate, 2 kHz.
sim three_mass_estimation_chirp --model three-mass --excitation chirp --duration 18 --seed 1
sim three_mass_validation_multisine --model three-mass --excitation multisine --duration 12 \
  --seed 2

# Chapters 6-7: multisine 2 pi k/12 rad/s, k = 1..360 (0-60 pi rad/s, (6.50)), two 12 s
# periods at the controller's 2 kHz (decimated to 200 Hz by the recursive estimator, after the
# motor velocity is differentiated from the angle at the full rate); the amplitude of a
# designed experiment (0.2 rad, Section 6.6.2: "the input can be chosen almost freely"), so
# that the excitation, not the load noise, dominates the torque. The same seed, so that only
# the fault differs between the logs.
diag=(--model three-mass --excitation multisine --amplitude 0.2 --duration 24 --seed 6)
sim diagnosis_no_fault "${diag[@]}"
sim diagnosis_fault_k_T "${diag[@]}" --param k_T=1.2              # k_T up 20 %
sim diagnosis_fault_J_a_inv "${diag[@]}" --param J_a=1.4333333333333333  # 1/J_a up 20 %
sim diagnosis_fault_f_m "${diag[@]}" --param f_m=0.0426           # f_m up 20 %

# Chapter 7 beyond the seed: the fault steps in at 12 s, in the middle of the log (the seed
# starts the estimator off the nominal value instead); the same experiment design as above,
# another seed, so that the healthy reference (diagnosis_no_fault) and the monitored logs are
# different experiments.
step=(--model three-mass --excitation multisine --amplitude 0.2 --duration 24 --seed 8)
sim diagnosis_step_none "${step[@]}"                                   # healthy throughout
sim diagnosis_step_k_T "${step[@]}" --step k_T=1.2@12                  # k_T up 20 % at 12 s
sim diagnosis_step_J_a_inv "${step[@]}" --step J_a=1.4333333333333333@12  # 1/J_a up 20 %
sim diagnosis_step_f_m "${step[@]}" --step f_m=0.0426@12               # f_m up 20 % at 12 s

# One log per effect (default effect parameters), three-mass arm, chirp, 1 kHz, 10 s. The
# ripple log adds a constant motor speed of 5 rad/s so that the motor turns several
# revolutions and the ripple is periodic in time.
effect_log=(--model three-mass --excitation chirp --duration 10 --rate 1000 --seed 7)
for effect in coulomb_friction backlash nonlinear_spring input_delay extra_mass; do
  sim "effect_$effect" "${effect_log[@]}" --effect "$effect"
done
sim effect_torque_ripple "${effect_log[@]}" --effect torque_ripple --reference-velocity 5

# A log whose time stamps a logger spoiled, for resampling: the three-mass chirp log, 6 s at
# 2 kHz, with data rows 3000 and 7000-7002 dropped, row 5000 stamped 15 us (3 %) late, row
# 9000 written twice and rows 10000 and 10001 swapped.
sim three_mass_irregular_timing --model three-mass --excitation chirp --duration 6 --seed 4
awk -F, -v OFS=, '
  /^#/ || !header { print; if (!/^#/) header = 1; next }
  { r = row++ }
  r == 3000 || (r >= 7000 && r <= 7002) { next }
  r == 5000 { $1 = sprintf("%.9f", $1 + 0.000015) }
  r == 9000 { print }
  r == 10000 { held = $0; next }
  { print }
  r == 10001 { print held }
' "$out/three_mass_irregular_timing.csv" > "$out/three_mass_irregular_timing.tmp"
mv "$out/three_mass_irregular_timing.tmp" "$out/three_mass_irregular_timing.csv"

if [[ $check -eq 1 ]]; then
  status=0
  for f in "$out"/*; do
    name="$(basename "$f")"
    if ! cmp -s "$f" "$target/$name"; then
      echo "make_sample_logs.sh: $name differs from $target/$name" >&2
      status=1
    fi
  done
  for f in "$target"/*.csv "$target"/*.truth.json; do
    [[ -e "$out/$(basename "$f")" ]] || { echo "extra file $f" >&2; status=1; }
  done
  [[ $status -eq 0 ]] && echo "all $(ls "$out" | wc -l) sample files regenerate bit-identically"
  exit $status
fi
echo "wrote $(ls "$out"/*.csv | wc -l) logs to $out"
