#!/usr/bin/env bash
# One run of every measurement the performance docs show, then their tables rewritten
# (scripts/perf_tables.py) and the chart redrawn. Run it on an IDLE machine: wall-clock
# numbers taken while other work runs are not results (the load before and after is
# written into the docs with the numbers).
#
#   bash scripts/perf-report.sh               # everything (about 15 min on 2 cores)
#   OUT=/tmp/perf bash scripts/perf-report.sh # where the raw results go (default
#                                             # target/perf-report; kept for inspection)
#   SKIP="callgrind load" bash scripts/perf-report.sh   # leave steps out: bench peers
#                                             # extra callgrind load frame4k docs
#   THREADS=2 SIZE=1920x1080 bash scripts/perf-report.sh
#   QUICK=1 SKIP=docs OUT=/tmp/pr bash scripts/perf-report.sh  # a smoke test of the
#             script (small maps and frames, one pass, no callgrind, no ffmpeg or nona;
#             its numbers mean nothing; with docs in SKIP nothing is written into the
#             repository, then `python3 scripts/perf_tables.py /tmp/pr` shows the tables)
#
# Steps (each writes into $OUT; a skipped step leaves its doc tables as they were):
#   bench     scripts/peers.py: `viewer bench` (8192x4096 map, $THREADS threads; all
#             configurations, the minification set, the chart docs/img/speed_error.png)
#             and every peer (OpenCV remap, numpy+remap, ffmpeg v360, py360convert, nona)
#             on the same views; then the chart redrawn with the peers (`viewer bench
#             --replot main/ours.json --peers main/peers.json`); OpenCV's remaps in three
#             rounds taking turns with ours (`peers.py --rounds 3`: a drifting VM weighs
#             on both alike)                                     -> main/{ours,peers}.json
#   extra     the OpenCV remap peers again with 1 thread, and with the 4096x2048 map on
#             1 and $THREADS threads (viewer bench without cube/minify rows)
#                                                    -> t1/, map4k/, map4k-t1/ peers.json
#   frame4k   a 3840x2160 bilinear pan from the 8k map (examples/frame_cost) -> frame4k.txt
#   load      `viewer bench-load --passes 3` (8k, 16k, 32k JPEGs: load, tables, frames,
#             memory; frame times the medians of three passes taking turns), and the 8k
#             and 32k pans again at hfov 120                 -> load.json, load120.json
#   callgrind scripts/kernel-cost.sh: instructions per pixel per kernel, and per view
#             (valgrind; independent of the load)      -> kernel-cost.md, views-cost.md
#   docs      scripts/perf_tables.py $OUT: the tables between the perf-report markers of
#             docs/performance.md and docs/huge.md
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-target/perf-report}
THREADS=${THREADS:-2}
SIZE=${SIZE:-1920x1080}
SKIP=${SKIP:-}
# The sizes (QUICK: a smoke test of this script, not a measurement).
map8k=8192x4096 map4k=4096x2048 passes=3 reps=3 frames=36 cfr=30 size4k=3840x2160 main_peers= lpasses=3 rounds=3
widths=8k,16k,32k widths120=8k,32k plot=$PWD/docs/img/speed_error.png
if [ -n "${QUICK:-}" ]; then
  SIZE=320x180 map8k=1024x512 map4k=512x256 passes=1 reps=1 frames=4 cfr=2 lpasses=1 rounds=1
  size4k=640x360 widths=1k,2k widths120=1k plot=$OUT/speed_error.png
  SKIP="$SKIP callgrind" main_peers="--no-ffmpeg --no-nona"
fi
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
[ -n "${QUICK:-}" ] && plot=$OUT/speed_error.png
skip() { [[ " $SKIP " == *" $1 "* ]]; }
say() { echo "perf-report: $(date -u +%T) $*" >&2; }
start=$(date +%s)
load_before=$(cut -d' ' -f1-3 /proc/loadavg)

say "building (release)"
cargo build --release -q -p viewer
cargo build --release -q -p lut-core --example frame_cost
viewer=$PWD/target/release/viewer

if ! skip bench; then
  say "viewer bench + all peers (map 8192x4096, $THREADS threads)"
  mkdir -p "$OUT/main"
  # shellcheck disable=SC2086 # main_peers is a list of flags
  python3 scripts/peers.py --size "$SIZE" --threads "$THREADS" --out "$OUT/main" --reps "$reps" \
    --rounds "$rounds" $main_peers \
    --bench-args "--passes $passes --map-size $map8k --plot $plot" >"$OUT/main/peers.txt"
  # The chart again, now with the peers of this run (measures nothing).
  "$viewer" bench --replot "$OUT/main/ours.json" --peers "$OUT/main/peers.json" --plot "$plot"
fi

if ! skip extra; then
  quick="--passes $passes --no-cube --no-minify"
  for run in "t1 $map8k 1" "map4k $map4k $THREADS" "map4k-t1 $map4k 1"; do
    read -r name map threads <<<"$run"
    say "OpenCV remap peers: map $map, $threads thread(s)"
    python3 scripts/peers.py --size "$SIZE" --threads "$threads" --out "$OUT/$name" \
      --reps "$reps" --rounds "$rounds" --no-ffmpeg --no-py360 --no-nona \
      --bench-args "$quick --map-size $map" >"$OUT/$name.txt"
  done
fi

if ! skip frame4k; then
  say "3840x2160 frames from the 8k map"
  target/release/examples/frame_cost size="$size4k" map="$map8k" sampler=bilinear \
    threads="$THREADS" frames="$cfr" >"$OUT/frame4k.txt"
fi

if ! skip load; then
  say "viewer bench-load"
  # Three passes, the maps taking turns, frame times the medians over the passes: the
  # 8k and 32k children run seconds apart, and this VM's speed drifts by 20-30 %.
  "$viewer" bench-load --json --widths "$widths" --frames "$frames" --passes "$lpasses" \
    >"$OUT/load.json"
  "$viewer" bench-load --json --widths "$widths120" --frames "$frames" --hfov 120 \
    --passes "$lpasses" >"$OUT/load120.json"
fi

if ! skip callgrind; then
  say "callgrind instruction counts"
  bash scripts/kernel-cost.sh >"$OUT/kernel-cost.md"
  KERNELS="scalar avx2" \
    VIEWS="pitch=0 hfov=90;pitch=45 hfov=90;pitch=80 hfov=90;pitch=10 hfov=30;pitch=10 hfov=150" \
    bash scripts/kernel-cost.sh >"$OUT/views-cost.md"
fi

minutes=$(awk -v s="$start" -v e="$(date +%s)" 'BEGIN { printf "%.1f", (e - s) / 60 }')
kernel=$(target/release/examples/frame_cost frames=0 map=64x32 size=64x32 2>/dev/null | cut -d'|' -f1)
python3 - "$OUT/machine.json" "$load_before" "$minutes" "$kernel" <<'EOF'
import json, os, subprocess, sys, datetime
path, before, minutes, kernel = sys.argv[1:5]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
mem = next((int(l.split()[1]) for l in open("/proc/meminfo") if l.startswith("MemTotal")), 0)
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
json.dump({
    "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
    "commit": commit, "nproc": os.cpu_count(), "cpu": cpu, "mem_gb": round(mem / 1e6),
    "load_before": before, "load_after": " ".join(open("/proc/loadavg").read().split()[:3]),
    "kernel": kernel.strip(), "minutes": float(minutes),
}, open(path, "w"), indent=2)
EOF

if ! skip docs; then
  python3 scripts/perf_tables.py "$OUT"
fi
say "done in $minutes min; raw results in $OUT"
