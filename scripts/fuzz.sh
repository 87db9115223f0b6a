#!/usr/bin/env bash
# Coverage-guided fuzzing of every parser lutpano owns or drives (fuzz/, cargo-fuzz and
# libFuzzer; see docs/reliability.md). Builds the targets once, then runs each for a given
# time, JOBS at a time (default 2: the two cores), niced, and prints one line per target:
# executions, executions per second, coverage (libFuzzer's cov = edges, ft = features),
# corpus size and what was found.
#
# Usage: scripts/fuzz.sh [--time SECONDS] [--runs N] [--jobs N] [--sanitizer none|address]
#                        [--ci] [--install] [TARGET...]
#   --time S       seconds per target (default 60)
#   --runs N       stop a target after N executions (or at --time, whichever comes first)
#   --jobs N       targets run at once (default 2)
#   --sanitizer X  none (default: Rust's own checks plus overflow checks, 2-3x faster) or
#                  address (AddressSanitizer, for the decoders' unsafe code)
#   --ci           run on a throw-away copy of the committed seeds (fuzz/seeds and the
#                  test data), keeping nothing; implies --install
#   --install      install what is missing: the nightly toolchain, cargo-fuzz
#   TARGET...      default: every target (fuzz/fuzz_targets/*.rs)
# Environment: NICE (default 10), FUZZ_LOG (folder for the logs, default
# target/fuzz-logs).
#
# Outside --ci the growing corpus is kept in fuzz/corpus/TARGET (ignored by git) and
# every crash, hang (a unit running more than 10 s) or runaway allocation (over 512 MB at
# once, 2 GB in all) is saved in fuzz/artifacts/TARGET/. Exits nonzero when any target
# found something; reproduce with `fuzz/target/SANITIZER/x86_64-unknown-linux-gnu/
# release/TARGET ARTIFACT`, then make it a regression test.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD

TIME=60
RUNS=-1
JOBS=2
SAN=none
CI=0
INSTALL=0
TARGETS=()
while [ $# -gt 0 ]; do
  case $1 in
    --time) TIME=$2; shift ;;
    --runs) RUNS=$2; shift ;;
    --jobs) JOBS=$2; shift ;;
    --sanitizer) SAN=$2; shift ;;
    --ci) CI=1; INSTALL=1 ;;
    --install) INSTALL=1 ;;
    -h|--help) sed -n '2,29p' "$0"; exit 0 ;;
    -*) echo "fuzz.sh: unknown option '$1'" >&2; exit 2 ;;
    *) TARGETS+=("$1") ;;
  esac
  shift
done
case $SAN in none|address) ;; *) echo "fuzz.sh: --sanitizer none or address" >&2; exit 2 ;; esac
NICE=${NICE:-10}
LOG=${FUZZ_LOG:-$ROOT/target/fuzz-logs}
mkdir -p "$LOG"

# In CI a machine that cannot get the fuzzing tools (some machines reach only package
# registries, so no second Rust toolchain can be fetched) skips the fuzz runs with a loud
# line instead of failing the whole suite; a build or a run that fails still fails.
cannot_install() {
  if [ "$CI" = 1 ]; then
    echo "== FUZZING SKIPPED: $1 (the fuzz targets need the nightly toolchain and cargo-fuzz)"
    exit 0
  fi
  echo "fuzz.sh: $1" >&2
  exit 1
}
if [ "$INSTALL" = 1 ]; then
  if ! rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    echo "== installing the nightly toolchain"
    rustup toolchain install nightly --profile minimal ||
      cannot_install "the nightly toolchain could not be installed"
  fi
  if ! command -v cargo-fuzz >/dev/null; then
    echo "== installing cargo-fuzz"
    t0=$SECONDS
    cargo install cargo-fuzz --version 0.13.2 --locked ||
      cannot_install "cargo-fuzz could not be installed"
    echo "== cargo-fuzz installed in $((SECONDS - t0)) s"
  fi
fi
command -v cargo-fuzz >/dev/null || { echo "fuzz.sh: cargo-fuzz not found (run with --install)" >&2; exit 1; }

if [ ${#TARGETS[@]} -eq 0 ]; then
  for f in fuzz/fuzz_targets/*.rs; do TARGETS+=("$(basename "$f" .rs)"); done
fi

echo "== building the fuzz targets (sanitizer $SAN)"
t0=$SECONDS
(cd fuzz && nice -n "$NICE" cargo +nightly fuzz build -O -a -s "$SAN" --target-dir "target/$SAN")
echo "== built in $((SECONDS - t0)) s"
BIN=$ROOT/fuzz/target/$SAN/x86_64-unknown-linux-gnu/release

# Further seed folders of committed test data, per target.
extra_seeds() {
  case $1 in
    ies|light_table) echo tests/data/ies tests/data/ldt ;;
    ldt) echo tests/data/ldt ;;
    map_jpeg) echo tests/data/jpeg tests/data/cube/skyfantasy ;;
  esac
}

SCRATCH=""
if [ "$CI" = 1 ]; then
  SCRATCH=$(mktemp -d)
  trap 'rm -rf "$SCRATCH"' EXIT
fi

# Run one target; its summary line goes to $LOG/TARGET.summary.
run_one() {
  local t=$1 corpus art
  if [ "$CI" = 1 ]; then
    corpus=$SCRATCH/corpus/$t
    art=$SCRATCH/artifacts/$t/
  else
    corpus=$ROOT/fuzz/corpus/$t
    art=$ROOT/fuzz/artifacts/$t/
  fi
  mkdir -p "$corpus" "$art"
  local dirs=("$corpus")
  [ -d "fuzz/seeds/$t" ] && dirs+=("fuzz/seeds/$t")
  for d in $(extra_seeds "$t"); do dirs+=("$d"); done
  local log=$LOG/$t.log rc=0 t0=$SECONDS
  nice -n "$NICE" "$BIN/$t" "${dirs[@]}" -max_total_time="$TIME" -runs="$RUNS" -timeout=10 \
    -rss_limit_mb=2048 -malloc_limit_mb=512 -print_final_stats=1 \
    -artifact_prefix="$art" >"$log" 2>&1 || rc=$?
  local done_line execs eps found
  done_line=$(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -n 1 || true)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  eps=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  local cov ft corp
  cov=$(echo "$done_line" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
  ft=$(echo "$done_line" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
  corp=$(echo "$done_line" | sed -n 's/.* corp: \([^ ]*\).*/\1/p')
  found=$(ls -A "$art" | tr '\n' ' ')
  [ "$rc" = 0 ] || found="exit $rc: ${found:-see $log}"
  printf '%-12s %12s execs in %5s s %8s/s  cov %6s  ft %6s  corpus %-12s %s\n' \
    "$t" "${execs:-?}" "$((SECONDS - t0))" "${eps:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" \
    "${found:-nothing found}" \
    | tee "$LOG/$t.summary"
  [ "$rc" = 0 ] && [ -z "$(ls -A "$art")" ]
}

echo "== fuzzing ${TARGETS[*]}: $TIME s each, $JOBS at a time (nice $NICE); logs in $LOG"
FAILED=0
running=0
for t in "${TARGETS[@]}"; do
  [ -x "$BIN/$t" ] || { echo "fuzz.sh: no target '$t'" >&2; exit 2; }
  run_one "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$JOBS" ]; then
    wait -n || FAILED=1
    running=$((running - 1))
  fi
done
while [ "$running" -gt 0 ]; do
  wait -n || FAILED=1
  running=$((running - 1))
done
if [ "$FAILED" = 1 ]; then
  echo "fuzz.sh: something was found (see the lines above and $LOG)" >&2
  exit 1
fi
echo "== fuzzing done: nothing found"
