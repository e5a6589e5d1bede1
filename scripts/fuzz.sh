#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, AddressSanitizer + UndefinedBehaviorSanitizer) and runs
# each for a set time on a corpus seeded from tests/data and sample_logs; prints executions and
# crashes per target and exits non-zero when any target crashed, leaked or hung.
#
#   bash scripts/fuzz.sh [--seconds N] [--seed N] [TARGET...]
#
# TARGET: fuzz_csv fuzz_table fuzz_mat fuzz_mat73 fuzz_session fuzz_cli_options fuzz_diagnose_log
#         fuzz_manifest fuzz_store
# (default: all).
# The corpus grows in $FUZZ_DIR/corpus/TARGET (default build-fuzz/); crashing inputs are kept
# in $FUZZ_DIR/artifacts. BUILD_DIR reuses an existing build configured with FLEXARM_FUZZ=ON
# (scripts/sanitize.sh makes one).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds=60
fuzz_seed=0  # libFuzzer's: 0 draws one; a fixed one repeats the same mutations (CI)
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --seed) fuzz_seed="$2"; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_csv fuzz_table fuzz_mat fuzz_mat73 fuzz_session fuzz_cli_options fuzz_diagnose_log
  fuzz_manifest fuzz_store)

build="${BUILD_DIR:-$here/build-fuzz}"
fuzzdir="${FUZZ_DIR:-$build}"
if [ ! -f "$build/CMakeCache.txt" ] || ! grep -q "FLEXARM_FUZZ:BOOL=ON" "$build/CMakeCache.txt"; then
  bash "$here/scripts/sanitize.sh" --configure-only "$build"
fi
cmake --build "$build" -j "${JOBS:-$(nproc)}" --target "${targets[@]}"

# Seeds: the inputs the tests already use, good and bad, plus the heads of the sample logs.
seed() {  # seed TARGET FILE... (the first 8 KiB of each; SEED_BYTES for more)
  local dir="$fuzzdir/corpus/$1"; shift
  mkdir -p "$dir"
  for f in "$@"; do
    [ -f "$f" ] && head -c "${SEED_BYTES:-8192}" "$f" > "$dir/seed-$(basename "$f")"
  done
  return 0
}
d="$here/tests/data"
seed fuzz_csv "$d"/bad/*.csv "$d"/hostile/*.csv "$d"/good/*.csv "$here"/sample_logs/effect_backlash.csv
seed fuzz_table "$d"/bad/*.dat "$d"/good/*.dat "$here"/sample_logs/daisy_robot_arm.dat
seed fuzz_mat "$d"/bad/*.mat "$d"/hostile/*.mat "$d"/good/*.mat
seed fuzz_session "$here"/sample_logs/sample_session.json "$d"/hostile/*.json
# v7.3 files are walked whole: seeds up to the 64 KiB an input may have.
SEED_BYTES=65536 seed fuzz_mat73 "$d"/hostile/v73_*.mat
seed fuzz_diagnose_log "$d"/hostile/dead_*.csv "$d"/hostile/time_step_1e6.csv "$d"/hostile/controller_*.csv \
  "$d"/good/small_log.csv "$here"/sample_logs/diagnosis_step_k_T.csv
mkdir -p "$fuzzdir/corpus/fuzz_cli_options"
printf 'x\0--model\0arx:2,2,1\0--range\0002:10\0--max-iterations\00050' > "$fuzzdir/corpus/fuzz_cli_options/seed-fit"
printf 'x\0--input-column\0003\0--sample-time=0.01\0--format\0table\0--fix\0backlash:2e-4' \
  > "$fuzzdir/corpus/fuzz_cli_options/seed-log"
mkdir -p "$fuzzdir/corpus/fuzz_manifest"
printf '# flexarm-fleet: 1\nrobot,axis,time,log,temperature_c,role\nR01,1,2026-03-01T06:00:00Z,R01/a.csv,24.5,reference\nR01,1,2026-03-02T06:00,R01/b.csv,,\nR02,3,2026-03-02,../x.csv,,\n' \
  > "$fuzzdir/corpus/fuzz_manifest/seed-plant"
printf '\xef\xbb\xbf# flexarm-fleet: 1\nlog,time,axis,robot\nb.csv,2026-03-05T06:00,2,R07\n' > "$fuzzdir/corpus/fuzz_manifest/seed-bom"
seed fuzz_manifest "$d"/fuzz/manifest_*.csv
# A store as FlexArm lays it out (its schema read from core/fleet/store.cpp), one log in it;
# the first byte selects the store half of the target.
mkdir -p "$fuzzdir/corpus/fuzz_store"
python3 - "$here/core/fleet/store.cpp" "$fuzzdir/corpus/fuzz_store" <<'PY' || true
import re, sqlite3, sys, os, tempfile
schema = re.search(r'R"sql\((.*?)\)sql"', open(sys.argv[1]).read(), re.S).group(1)
path = os.path.join(tempfile.mkdtemp(), "s.sqlite")
db = sqlite3.connect(path)
db.executescript(schema)
a, r = "a" * 64, "0" * 64
db.execute("INSERT INTO meta VALUES('schema_version', '1')")
db.execute("INSERT INTO logs VALUES(?, ?, 'R01', 1, '2026-03-01', 20513.25, 'a.csv', 25, '', 1, 'ok', 'none', NULL, 0.1, 1)", (a, r))
for i, (n, v) in enumerate([("k_T", 0.5), ("J_a", 1.7), ("f_m", 0.036)]):
    db.execute("INSERT INTO estimates VALUES(?, ?, ?, ?, 0.01, ?, ?)", (a, r, n, v, v, i))
db.commit(); db.close()
open(os.path.join(sys.argv[2], "seed-store"), "wb").write(b"\x01" + open(path, "rb").read())
open(os.path.join(sys.argv[2], "seed-result"), "wb").write(
    b'\x00{"sha256":"' + a.encode() + b'","reference_sha256":"' + r.encode() +
    b'","ok":true,"message":"","verdict":"none","verdict_time_s":null,"seconds":0.1,'
    b'"estimates":[{"name":"k_T","value":0.5,"std":0.01,"reference":0.5}]}')
PY
mkdir -p "$fuzzdir/artifacts"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

status=0
printf '%-18s %14s %10s %8s  %s\n' target executions exec/s crashes result
for t in "${targets[@]}"; do
  log="$fuzzdir/$t.log"
  rc=0
  touch "$tmp/start"
  FLEXARM_FUZZ_TMP="$tmp" ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1" \
    LSAN_OPTIONS="suppressions=$here/tests/sanitizer/lsan.supp" \
    "$build/fuzz/$t" "$fuzzdir/corpus/$t" -max_total_time="$seconds" -seed="$fuzz_seed" \
    -print_final_stats=1 -rss_limit_mb=2048 -timeout=10 -max_len=65536 \
    -artifact_prefix="$fuzzdir/artifacts/$t-" > "$log" 2>&1 || rc=$?
  execs=$( (grep -h "stat::number_of_executed_units" "$log" || true) | awk '{s += $2} END {print s + 0}')
  rate=$(( execs / (seconds > 0 ? seconds : 1) ))
  crashes=$(find "$fuzzdir/artifacts" -name "$t-*" -newer "$tmp/start" | wc -l)
  result=ok
  if [ "$rc" -ne 0 ] || [ "$crashes" -ne 0 ]; then result="FAILED (see $log)"; status=1; fi
  printf '%-18s %14s %10s %8s  %s\n' "$t" "$execs" "$rate" "$crashes" "$result"
done
exit $status
