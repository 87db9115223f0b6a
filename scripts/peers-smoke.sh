#!/usr/bin/env bash
# A smoke test of the measuring scripts (not a measurement: tiny sizes, one repetition,
# the numbers mean nothing): scripts/peers.py with the view sets and with --view, and the
# chart redrawn from its files (`viewer bench --replot --peers`), on the binary the test
# run built. perf-report.sh runs these on an idle machine for the docs; a fault in them
# would otherwise only show there (the --view work once broke every peers run).
# Needs OpenCV for Python (installed with pip when missing; skipped LOUDLY if it cannot be).
set -euo pipefail
cd "$(dirname "$0")/.."
VIEWER_BIN=${VIEWER_BIN:-target/ci/viewer}
if ! python3 -c 'import cv2, numpy' 2>/dev/null; then
  python3 -m pip install -q opencv-python-headless numpy >/dev/null 2>&1 || true
fi
if ! python3 -c 'import cv2, numpy' 2>/dev/null; then
  echo "warning: opencv-python-headless could not be installed: the peers script's smoke test is SKIPPED" >&2
  exit 0
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
common=(--size 160x90 --threads 2 --viewer "$VIEWER_BIN" --reps 1 --no-install --no-ffmpeg
  --no-nona --no-py360)
bench="--passes 1 --map-size 512x256 --no-cube --no-minify"
python3 scripts/peers.py "${common[@]}" --out "$out/sets" --bench-args "$bench" >"$out/sets.txt"
python3 scripts/peers.py "${common[@]}" --out "$out/views" --rounds 2 --view 30,0,90 \
  --view 30,90,90 --bench-args "$bench" >"$out/views.txt"
"$VIEWER_BIN" bench --replot "$out/sets/ours.json" --peers "$out/sets/peers.json" \
  --plot "$out/chart.png"
python3 - "$out" <<'PY'
import json, sys, os
out = sys.argv[1]
for run in ("sets", "views"):
    p = json.load(open(os.path.join(out, run, "peers.json")))
    rows = p.get("rows") or []
    assert rows, f"{run}: peers.json has no rows"
    txt = open(os.path.join(out, run + ".txt")).read()
    assert "OpenCV remap" in txt, f"{run}: no OpenCV rows in the table"
pv = json.load(open(os.path.join(out, "views", "peers.json")))["per_view"]
assert [r["view"] for r in pv] == [[30, 0, 90], [30, 90, 90]], pv
assert os.path.getsize(os.path.join(out, "chart.png")) > 10000, "the chart is (nearly) empty"
print("peers-smoke: peers.py (view sets, --view with 2 rounds) and the replotted chart: ok")
PY
