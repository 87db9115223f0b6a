#!/usr/bin/env bash
# Window soak: drives the real viewer window under Xvfb for a given time with random
# (seeded) user actions — drags, flicks, wheel, keys, resize storms, minimizing (unmapped,
# and shrunk to 1x1) and back, fullscreen, dropping good and bad files (a truncated JPEG,
# header-only files claiming huge sizes, a text file, a FIFO, a symbolic-link loop, a
# damaged EXR, a cube folder, a cube layout image, an IES light, a tour and a tiled
# pyramid, and damaged ones of each), the next/previous file
# in the folder (bad ones among them), the Open and Save dialogs (a view saved with
# Enter), the help overlay, and clicks all over the panel (every menu, checkbox, slider
# and button it has) — while sampling the process's resident memory (VmRSS from /proc)
# to a CSV once a second. The settings live in a folder of the run (LUTPANO_CONFIG_DIR,
# starting with the panel shown), never the real home.
#
# Passes when: the viewer never exits or panics, every drop is taken (the XDND exchange
# completes, so the window never stopped answering), the window still answers at the end
# (a turn, then R back to the start view; Ctrl+Q exits 0), and — for runs of 5 minutes
# or more — the resident memory stays flat after the warm-up (the first fifth of the run,
# at least 60 s): every twelfth of the run the soak returns to one checkpoint state (the
# sample panorama loaded, MAX_LIGHTS lights, rectilinear, 800x500, auto-rotation off,
# idle) and reads VmRSS (and its anonymous, file and shared parts); every
# checkpoint after the warm-up must be within 5 % of the first one after it. (The
# once-a-second curve is reported too, not judged: it follows what is on show — a cube,
# an EXR, how many lights.) Shorter runs (CI's minute) report without judging: their
# warm-up is not over.
#
# Output in target/window-soak/: rss.csv (seconds, VmRSS kB, frames so far),
# checkpoints.csv (seconds, VmRSS kB, lights), rss-table.md (the memory curve: one row
# per tenth of the run, and the checkpoints), summary.txt, the viewer's logs.
#
# Usage: scripts/window-soak.sh [--duration SECONDS] [--seed N] [--install] [--no-build] [--heap]
#   --duration S  how long to drive the window (default 600)
#   --seed N      the random seed (default 1): the same seed repeats the same actions
#   --install     apt-get the X tools first (as scripts/window-smoke.sh --install, plus
#                 python3-xlib for the drops)
#   --no-build    use the existing release binary
#   --heap        at each checkpoint also read glibc's own heap figures (gdb attaches and
#                 calls malloc_stats(): bytes in use by live allocations, and bytes held
#                 from the system) into checkpoints.csv: live bytes growing means a
#                 leak, flat live bytes under a growing RSS means the allocator retains
#                 freed memory (needs gdb and glibc; the viewer pauses for a moment)
# Honours CARGO_TARGET_DIR; VIEWER_BIN=path tests another binary (implies --no-build);
# SOAK_OUT=folder puts the output elsewhere.
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=${SOAK_OUT:-$ROOT/target/window-soak}
DURATION=600
SEED=1
INSTALL=0
BUILD=1
HEAP=0
while [ $# -gt 0 ]; do
  case $1 in
    --duration) DURATION=$2; shift ;;
    --seed) SEED=$2; shift ;;
    --install) INSTALL=1 ;;
    --no-build) BUILD=0 ;;
    --heap) HEAP=1 ;;
    -h|--help) sed -n '2,42p' "$0"; exit 0 ;;
    *) echo "window-soak: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done

fail() { echo "window-soak: FAIL: $*" >&2; exit 1; }
log() { echo "window-soak: $*"; }
# shellcheck source=scripts/lib/xvfb.sh
. scripts/lib/xvfb.sh

[ "$INSTALL" = 0 ] || xvfb_install python3-xlib
PY=/usr/bin/python3
TOOLS="Xvfb xdotool xdpyinfo mkfifo"
[ "$HEAP" = 0 ] || TOOLS="$TOOLS gdb"
for tool in $TOOLS; do
  command -v "$tool" >/dev/null || fail "$tool not found (run with --install)"
done
"$PY" -c 'import Xlib' 2>/dev/null || fail "python3-xlib not found (run with --install)"

TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
[ -z "${VIEWER_BIN:-}" ] || BUILD=0
if [ "$BUILD" = 1 ]; then
  log "building the release binary"
  cargo build --release -p viewer --bin viewer
fi
BIN=${VIEWER_BIN:-$TARGET/release/viewer}
case $BIN in /*) ;; *) BIN=$ROOT/$BIN ;; esac
[ -x "$BIN" ] || fail "$BIN not found"

rm -rf "$OUT"
mkdir -p "$OUT/files" "$OUT/work" "$OUT/config"
echo '{"panel": true, "save_dir": "'"$OUT/work"'"}' >"$OUT/config/settings.json"
export LUTPANO_CONFIG_DIR=$OUT/config
VIEWLOG=$OUT/viewer.stdout
ERRLOG=$OUT/viewer.stderr
CSV=$OUT/rss.csv

# --- the files to drop ------------------------------------------------------------------
F=$OUT/files
cp assets/courtyard.jpg "$F/pano.jpg"
cp tests/data/hdr/interior.exr "$F/interior.exr"
cp -r tests/data/cube/skyfantasy "$F/skyfantasy"
cp tests/data/ies/type_b_full.ies "$F/lamp.ies"
"$BIN" render "$F/pano.jpg" -o "$F/view.png" --size 512x256 --yaw 40
"$BIN" convert "$F/pano.jpg" "$F/cross.png" --to cube --layout cross --face-size 64
head -c 20000 assets/courtyard.jpg >"$F/truncated.jpg"
head -c "$(($(stat -c %s tests/data/hdr/interior.exr) * 6 / 10))" tests/data/hdr/interior.exr >"$F/cut.exr"
echo "not an image" >"$F/text.jpg"
mkfifo "$F/pipe.jpg"
ln -s loop-b.jpg "$F/loop-a.jpg"
ln -s loop-a.jpg "$F/loop-b.jpg"
"$PY" - "$F" <<'EOF'
import struct, sys, zlib
d = sys.argv[1]
# A PNG whose IHDR claims 100000 x 100000 and no pixels.
ihdr = b"IHDR" + struct.pack(">IIBBBBB", 100000, 100000, 8, 2, 0, 0, 0)
png = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + ihdr + struct.pack(">I", zlib.crc32(ihdr))
open(f"{d}/huge-header.png", "wb").write(png)
# A 2.3 KB JPEG whose SOF0 claims 32768 x 16384 (inside the default pixel limit).
sof = b"\xff\xc0\x00\x11\x08" + struct.pack(">HH", 16384, 32768) + b"\x03\x01\x22\x00\x02\x11\x01\x03\x11\x01"
com = b"\xff\xfe" + struct.pack(">H", 2280) + b"x" * 2278
open(f"{d}/claims-32k.jpg", "wb").write(b"\xff\xd8" + sof + com + b"\xff\xd9")
EOF
# A tour (its scenes open on the tour's links) and a tiled pyramid (a folder holding
# config.json); a damaged pyramid (a tile cut short, a tile that is a FIFO, a tile of
# text) and a damaged tour (a scene whose panorama is missing, control characters and a
# 100 000-character title).
cp -r tests/data/tours/pannellum "$F/tour"
cp -r tests/data/multires/generate-py "$F/pyramid"
cp -r tests/data/multires/generate-py "$F/bad-pyramid"
tiles=("$F"/bad-pyramid/1/*.jpg)
head -c "$(($(stat -c %s "${tiles[0]}") / 2))" "${tiles[0]}" >"$F/cut-tile" && mv "$F/cut-tile" "${tiles[0]}"
rm "${tiles[1]}" && mkfifo "${tiles[1]}"
echo "not a tile" >"${tiles[2]}"
"$PY" - "$F" <<'EOF'
import json, sys
d = sys.argv[1]
tour = {"default": {"firstScene": "a"}, "scenes": {
    "a": {"title": "\x1b]0;owned\x07" + "t" * 100000, "panorama": "pano.jpg",
          "hotSpots": [{"pitch": 0, "yaw": 10, "type": "scene", "sceneId": "b"}]},
    "b": {"panorama": "missing.jpg"}}}
open(f"{d}/bad-tour.json", "w").write(json.dumps(tour))
EOF
GOOD=("$F/pano.jpg" "$F/interior.exr" "$F/skyfantasy" "$F/view.png" "$F/cross.png" "$F/lamp.ies"
  "$F/tour/tour.json" "$F/pyramid")
BAD=("$F/truncated.jpg" "$F/cut.exr" "$F/text.jpg" "$F/pipe.jpg" "$F/loop-a.jpg" "$F/huge-header.png" "$F/claims-32k.jpg"
  "$F/bad-pyramid" "$F/bad-tour.json")

# --- X and the viewer -------------------------------------------------------------------
XVFB_PID=""
VIEWER_PID=""
SAMPLER_PID=""
cleanup() {
  [ -z "$SAMPLER_PID" ] || kill "$SAMPLER_PID" 2>/dev/null || true
  if [ -n "$VIEWER_PID" ] && kill -0 "$VIEWER_PID" 2>/dev/null; then kill "$VIEWER_PID" || true; fi
  if [ -n "$XVFB_PID" ] && kill -0 "$XVFB_PID" 2>/dev/null; then kill "$XVFB_PID" || true; fi
}
trap cleanup EXIT
xvfb_start 121 160 "$OUT/xvfb.log"

alive() { kill -0 "$VIEWER_PID" 2>/dev/null || fail "the viewer exited (see $ERRLOG)"; }
wait_for() { # pattern, from line, timeout
  local end=$((SECONDS + $3))
  while [ $SECONDS -lt "$end" ]; do
    tail -n +"$(($2 + 1))" "$VIEWLOG" | grep -q -- "$1" && return 0
    alive
    sleep 0.1
  done
  fail "timed out waiting for '$1' (see $VIEWLOG)"
}
lines() { wc -l <"$VIEWLOG"; }

log "starting the viewer"
for attempt in 1 2; do
  (cd "$OUT/work" && exec "$BIN" --size 800x500 --print-view) >"$VIEWLOG" 2>"$ERRLOG" &
  VIEWER_PID=$!
  sleep 1
  if kill -0 "$VIEWER_PID" 2>/dev/null || ! grep -q 'cannot open a window' "$ERRLOG"; then break; fi
  log "the viewer could not connect (attempt $attempt): $(cat "$ERRLOG")"
  sleep 1
done
wait_for '^loaded ' 0 60
wait_for '^view ' 0 60
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
[ -n "$WID" ] || fail "no viewer window found"

# Resident memory once a second: seconds since start, VmRSS in kB, frames so far.
echo "seconds,rss_kb,frames" >"$CSV"
(
  t0=$(date +%s.%N)
  while kill -0 "$VIEWER_PID" 2>/dev/null; do
    rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$VIEWER_PID/status" 2>/dev/null || true)
    frames=$(grep -c '^view ' "$VIEWLOG" || true)
    [ -n "$rss" ] && echo "$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}'),$rss,$frames" >>"$CSV"
    sleep 1
  done
) &
SAMPLER_PID=$!

# --- the actions ------------------------------------------------------------------------
RANDOM=$SEED
rnd() { echo $((RANDOM % $1)); } # 0..n-1
geom() { eval "$(xdotool getwindowgeometry --shell "$WID")"; }
focus() { xdotool windowfocus "$WID" 2>/dev/null || true; }
key() { focus; xdotool keydown "$1"; sleep 0.05; xdotool keyup "$1"; }
# Move the pointer, kept on the 1280x800 screen.
move() {
  local x=$1 y=$2
  [ "$x" -ge 0 ] || x=0; [ "$x" -le 1279 ] || x=1279
  [ "$y" -ge 0 ] || y=0; [ "$y" -le 799 ] || y=799
  xdotool mousemove "$x" "$y"
}
declare -A COUNT
DROPS_OK=0
act_drag() {
  geom; local sw=$((WIDTH > 300 ? WIDTH - 230 : WIDTH)) x y i
  x=$((X + 20 + $(rnd $((sw > 40 ? sw - 40 : 1))))); y=$((Y + 20 + $(rnd $((HEIGHT > 40 ? HEIGHT - 40 : 1)))))
  move "$x" "$y"; xdotool mousedown 1
  for i in $(seq 1 10); do move "$((x + (RANDOM % 41 - 20) * i / 2))" "$((y + (RANDOM % 21 - 10) * i / 2))"; sleep 0.02; done
  sleep 0.2; xdotool mouseup 1
}
act_flick() {
  geom; local x=$((X + 100 + $(rnd 200))) y=$((Y + 100 + $(rnd 200))) dx=$(( (RANDOM % 2) * 2 - 1 ))
  move "$x" "$y"; xdotool mousedown 1
  for i in 1 2 3 4 5; do move "$((x + dx * 25 * i))" "$((y + 3 * i))"; sleep 0.01; done
  xdotool mouseup 1
}
act_wheel() {
  geom; move "$((X + WIDTH / 3))" "$((Y + HEIGHT / 2))"
  local b=$((4 + $(rnd 2))) n=$((1 + $(rnd 5))) i
  for i in $(seq 1 "$n"); do xdotool click "$b"; sleep 0.03; done
}
KEYS=(Left Right Up Down a d w s plus minus r bracketleft bracketright Tab space question F1 v l)
act_key() { key "${KEYS[$(rnd ${#KEYS[@]})]}"; }
# A click in the scene, away from the panel: a panel text field or number being edited
# (a click on a number edits it) gives the keyboard back to the shortcuts.
unfocus() {
  geom
  move "$((X + (WIDTH > 300 ? WIDTH - 230 : WIDTH) / 2))" "$((Y + HEIGHT / 2))"
  xdotool click 1
  sleep 0.2
}
# Hide the panel and show it again (H), so the panel clicks find it.
act_panel_toggle() { key h; sleep 0.3; key h; }
# The next or previous file of the current one's folder (the drop folder: bad files too).
act_page() { if [ "$(rnd 2)" = 0 ]; then key Next; else key Prior; fi; }
chord() { focus; xdotool keydown "$1"; sleep 0.05; xdotool key "$2"; sleep 0.05; xdotool keyup "$1"; }
# The Open dialog, opened and closed again.
act_open_dialog() { chord ctrl o; sleep 0.5; key Escape; }
act_resize_storm() {
  local i
  for i in $(seq 1 12); do
    xdotool windowsize "$WID" "$((200 + $(rnd 1080)))" "$((150 + $(rnd 650)))" 2>/dev/null || true
    sleep 0.03
  done
}
act_minimize() {
  xdotool windowunmap "$WID"; sleep 0.3; xdotool windowmap "$WID"; sleep 0.2
  xdotool windowsize "$WID" 1 1; sleep 0.3; xdotool windowsize "$WID" 800 500; sleep 0.2
}
act_fullscreen() { key f; sleep 0.4; key Escape; }
drop_file() {
  timeout 20 "$PY" scripts/xdnd-drop.py "$WID" "$1" 2>>"$OUT/drops.log" ||
    fail "dropping $(basename "$1") was not taken: the window stopped answering (see $OUT/drops.log)"
  DROPS_OK=$((DROPS_OK + 1))
  echo "$(basename "$1")" >>"$OUT/dropped.txt"
}
# The lights of the last frame (each dropped IES file adds one; the panel removes them),
# and its output projection (V cycles them; the panel sets them).
lights_now() { grep '^view ' "$VIEWLOG" | tail -n 1 | sed -n 's/.* lights=\([0-9]*\).*/\1/p'; }
proj_now() { grep '^view ' "$VIEWLOG" | tail -n 1 | sed -n 's/.* proj=\([a-z]*\).*/\1/p'; }
MAX_LIGHTS=3
act_drop() {
  local f
  if [ "$(rnd 2)" = 0 ]; then f=${GOOD[$(rnd ${#GOOD[@]})]}; else f=${BAD[$(rnd ${#BAD[@]})]}; fi
  # At most MAX_LIGHTS lights, so that the checkpoints compare the same scene.
  [ "$f" != "$F/lamp.ies" ] || [ "${MAX_LIGHTS}" -gt "$(lights_now)" ] || f=$F/pano.jpg
  drop_file "$f"
}
act_panel() {
  geom
  [ "$WIDTH" -gt 300 ] || return 0
  local i
  for i in 1 2 3 4 5; do
    move "$((X + WIDTH - 228 + $(rnd 226)))" "$((Y + 2 + $(rnd $((HEIGHT - 4)))))"
    xdotool click 1
    sleep 0.1
  done
  key Escape # close a menu left open
}
# The Save dialog (P): Enter saves view-N.png in the run's work folder; Escape closes the
# dialog should the save not have closed it.
SAVES=0
# Like wait_for, but returns 1 on a time-out.
wait_new() { timeout "$3" bash -c "until tail -n +$(($2 + 1)) '$VIEWLOG' | grep -q -- '$1'; do sleep 0.1; done"; }
# Wait until the window is idle: no new line for a second, the last frame at full quality.
idle() {
  local n
  for _ in $(seq 1 40); do
    n=$(lines)
    sleep 1
    [ "$(lines)" = "$n" ] && grep '^view ' "$VIEWLOG" | tail -n 1 | grep -q 'level=full' && return 0
  done
  return 1
}
# A checkpoint: the same state every time — dialogs, help and fullscreen closed, the
# window at 800x500, the sample panorama loaded, MAX_LIGHTS lights, the rectilinear
# projection, auto-rotation off, idle — and its
# resident memory. The memory of the checkpoints after the warm-up is what is judged.
CHECKS=$OUT/checkpoints.csv
echo "seconds,rss_kb,lights,projection,heap_inuse_kb,heap_system_kb,anon_kb,file_kb,shmem_kb" >"$CHECKS"
# glibc's heap at this moment (with --heap): "in use kB,system kB" of malloc_stats()'s
# total (arenas and mmapped blocks), printed by the viewer to its stderr; "," without.
heap_now() {
  [ "$HEAP" = 1 ] || { echo ","; return; }
  local n
  n=$(wc -l <"$ERRLOG")
  timeout 60 gdb -p "$VIEWER_PID" -batch -ex 'call (void)malloc_stats()' >>"$OUT/gdb.log" 2>&1 || true
  sleep 0.2
  tail -n +"$((n + 1))" "$ERRLOG" | awk '
    /^Total \(incl. mmap\):/ { t = 1; next }
    t && /^system bytes/ { sys = $NF }
    t && /^in use bytes/ { use = $NF }
    END { if (use != "") printf "%d,%d\n", use / 1024, sys / 1024; else print "," }'
}
checkpoint() {
  local n l
  for _ in 1 2 3; do key Escape; sleep 0.2; done
  unfocus
  xdotool windowmap "$WID" 2>/dev/null || true
  xdotool windowsize "$WID" 800 500
  sleep 0.5
  n=$(lines)
  drop_file "$F/pano.jpg"
  wait_for "^loaded $F/pano.jpg" "$n" 60
  wait_for '^view ' "$n" 60
  for _ in 1 2 3 4 5 6; do
    l=$(lights_now)
    [ "${l:-0}" -lt "$MAX_LIGHTS" ] || break
    n=$(lines)
    drop_file "$F/lamp.ies"
    wait_new "^view .*lights=$((l + 1))\$" "$n" 30 || true
  done
  for _ in 1 2 3 4 5 6; do
    [ "$(proj_now)" != rectilinear ] || break
    n=$(lines)
    key v
    wait_new '^view ' "$n" 30 || true
  done
  # Auto-rotation (Space, kept in the settings file) never lets the window idle: off.
  if grep -q '"auto_rotate": true' "$OUT/config/settings.json"; then
    key space
    sleep 1.5 # the settings file is written at most once a second
  fi
  idle || log "checkpoint: the window did not become idle in 40 s"
  local rss kinds
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$VIEWER_PID/status")
  # The resident set by kind: anonymous (the heap, stacks), files (the binary's and the
  # libraries' pages, faulted in as code runs), shared memory (softbuffer's image).
  kinds=$(awk '/^RssAnon:/ {a = $2} /^RssFile:/ {f = $2} /^RssShmem:/ {s = $2} END {print a "," f "," s}' "/proc/$VIEWER_PID/status")
  echo "$((SECONDS - START)),$rss,$(lights_now),$(proj_now),$(heap_now),$kinds" >>"$CHECKS"
}
act_save() {
  local n
  n=$(lines)
  key p
  if timeout 5 bash -c "until tail -n +$((n + 1)) '$VIEWLOG' | grep -q '^dialog save'; do sleep 0.1; done"; then
    sleep 0.3
    key Return
    timeout 20 bash -c "until tail -n +$((n + 1)) '$VIEWLOG' | grep -q '^saved \\|^save failed'; do sleep 0.1; done" &&
      SAVES=$((SAVES + 1))
  fi
  key Escape
}
ACTIONS=(drag drag flick wheel key key resize_storm minimize fullscreen drop drop panel panel panel
  panel_toggle page open_dialog save)

log "driving the window for $DURATION s (seed $SEED)"
START=$SECONDS
# The largest window of the run first (the whole screen, then fullscreen), inside the
# warm-up: buffers sized to the largest window so far and kept (egui_software_backend's
# canvas, softbuffer's shared image) reach their size before the checkpoints are judged.
xdotool windowsize "$WID" 1280 800 2>/dev/null || true
sleep 1
key f
sleep 1
key Escape
xdotool windowsize "$WID" 800 500 2>/dev/null || true
sleep 0.5
CHECK_EVERY=$((DURATION / 12 > 20 ? DURATION / 12 : 20))
LAST_CHECK=$START
while [ $((SECONDS - START)) -lt "$DURATION" ]; do
  if [ $((SECONDS - LAST_CHECK)) -ge "$CHECK_EVERY" ]; then
    checkpoint
    LAST_CHECK=$SECONDS
  fi
  a=${ACTIONS[$(rnd ${#ACTIONS[@]})]}
  "act_$a"
  COUNT[$a]=$((${COUNT[$a]:-0} + 1))
  alive
  sleep 0.$((1 + $(rnd 4)))
done

# --- the end: still answering? ----------------------------------------------------------
log "actions: $(for k in "${!COUNT[@]}"; do printf '%s=%s ' "$k" "${COUNT[$k]}"; done)"
xdotool windowmap "$WID" 2>/dev/null || true
xdotool windowsize "$WID" 800 500
sleep 1
# Close whatever is open (a dialog, the help, fullscreen), drop the sample again and wait
# for its load, turn (a new frame), then R: the start view of the sample is rendered.
# (R on a view already at its start renders nothing: hence the turn first.)
for _ in 1 2 3; do key Escape; sleep 0.3; done
unfocus
N=$(lines)
drop_file "$F/pano.jpg"
wait_for "^loaded $F/pano.jpg" "$N" 60
ok=0
for _ in 1 2 3; do
  N=$(lines)
  focus; xdotool keydown Left; sleep 0.6; xdotool keyup Left
  timeout 30 bash -c "until tail -n +$((N + 1)) '$VIEWLOG' | grep -q '^view yaw=-\\?\\([1-9]\\|0\\.0*[1-9]\\)'; do sleep 0.1; done" || continue
  N=$(lines)
  key r
  if timeout 30 bash -c "until tail -n +$((N + 1)) '$VIEWLOG' | grep -q 'yaw=0.0000 pitch=0.0000 hfov=90.0000'; do sleep 0.1; done"; then ok=1; break; fi
done
[ "$ok" = 1 ] || fail "the window did not turn and return to the start view (R) at the end"
alive
focus
xdotool keydown ctrl; sleep 0.1; xdotool key q; sleep 0.1; xdotool keyup ctrl
RC=""
for _ in $(seq 1 100); do
  if ! kill -0 "$VIEWER_PID" 2>/dev/null; then set +e; wait "$VIEWER_PID"; RC=$?; set -e; break; fi
  sleep 0.1
done
[ -n "$RC" ] || fail "the viewer did not close on Ctrl+Q"
VIEWER_PID=""
[ "$RC" = 0 ] || fail "the viewer exited with $RC (see $ERRLOG)"
! grep -q 'panicked' "$ERRLOG" || fail "the viewer panicked (see $ERRLOG)"
kill "$SAMPLER_PID" 2>/dev/null || true
wait "$SAMPLER_PID" 2>/dev/null || true
SAMPLER_PID=""

# --- the memory curve -------------------------------------------------------------------
FRAMES=$(grep -c '^view ' "$VIEWLOG" || true)
VARIETY=$(grep '^view ' "$VIEWLOG" | tr ' ' '\n' | grep -E '^(path|sampler|lights)=' | sort -u | tr '\n' ' ')
ERRORS=$(sort -u "$ERRLOG" | grep -c '^viewer: ' || true)
"$PY" - "$CSV" "$CHECKS" "$OUT/rss-table.md" <<'EOF' >"$OUT/memory.txt"
import csv, statistics, sys
rows = [(float(r["seconds"]), int(r["rss_kb"])) for r in csv.DictReader(open(sys.argv[1]))]
checks = [(float(r["seconds"]), int(r["rss_kb"]), r["lights"], r["projection"]) for r in csv.DictReader(open(sys.argv[2]))]
# The resident set by kind (anonymous, files, shared memory) in kB.
kinds = [(int(r["anon_kb"]), int(r["file_kb"]), int(r["shmem_kb"])) for r in csv.DictReader(open(sys.argv[2]))]
# glibc's live and held heap at the checkpoints (with --heap), in kB, or None.
heap = [(int(r["heap_inuse_kb"]), int(r["heap_system_kb"])) if r.get("heap_inuse_kb") else None
        for r in csv.DictReader(open(sys.argv[2]))]
if len(rows) < 10:
    print("FLAT no: too few samples"); sys.exit()
end = rows[-1][0]
warm = min(max(60.0, end / 5), end / 2)
# The curve: one row per tenth of the run after the warm-up (whatever was on show).
after = [r for r in rows if r[0] >= warm]
n = 10
span = (end - warm) / n
parts = [[kb for t, kb in after if warm + i * span <= t < warm + (i + 1) * span or (i == n - 1 and t >= end)] for i in range(n)]
with open(sys.argv[3], "w") as f:
    f.write("Every second (whatever was on show):\n\n")
    f.write("| from s | to s | RSS MiB min | median | max |\n|---:|---:|---:|---:|---:|\n")
    wu = [kb for t, kb in rows if t < warm]
    if wu:
        f.write(f"| 0 | {warm:.0f} (warm-up) | {min(wu)/1024:.1f} | {statistics.median(wu)/1024:.1f} | {max(wu)/1024:.1f} |\n")
    for i, p in enumerate(parts):
        if p:
            f.write(f"| {warm + i*span:.0f} | {warm + (i+1)*span:.0f} | {min(p)/1024:.1f} | {statistics.median(p)/1024:.1f} | {max(p)/1024:.1f} |\n")
    f.write("\nCheckpoints (the same state each time: the sample loaded, the same lights and projection, 800x500):\n\n")
    f.write("| s | RSS MiB | anonymous | files | shared | lights | projection | heap in use MiB | heap held MiB |\n"
            "|---:|---:|---:|---:|---:|---:|---|---:|---:|\n")
    for (t, kb, lights, proj), h, k in zip(checks, heap, kinds):
        hs = f"{h[0]/1024:.1f} | {h[1]/1024:.1f}" if h else "- | -"
        ks = " | ".join(f"{v/1024:.1f}" for v in k)
        f.write(f"| {t:.0f}{' (warm-up)' if t < warm else ''} | {kb/1024:.1f} | {ks} | {lights} | {proj} | {hs} |\n")
print(f"warm-up {warm:.0f} s; every second after it: {min(kb for _, kb in after)/1024:.1f} to "
      f"{max(kb for _, kb in after)/1024:.1f} MiB (what is on show varies)")
judged = [(t, kb) for t, kb, _, _ in checks if t >= warm]
if len(judged) < 3:
    print(f"FLAT no: {len(judged)} checkpoints after the warm-up, 3 needed"); sys.exit()
ref = judged[0][1]
dev = [(kb - ref) / ref for _, kb in judged]
print(f"{len(judged)} checkpoints after the warm-up: {min(kb for _, kb in judged)/1024:.1f} to "
      f"{max(kb for _, kb in judged)/1024:.1f} MiB, from {100*min(dev):+.1f} % to {100*max(dev):+.1f} % "
      f"of the first")
hj = [h for (t, _, _, _), h in zip(checks, heap) if t >= warm and h]
if hj:
    print(f"glibc heap at those checkpoints: in use {min(u for u, _ in hj)/1024:.1f} to "
          f"{max(u for u, _ in hj)/1024:.1f} MiB, held {min(s for _, s in hj)/1024:.1f} to "
          f"{max(s for _, s in hj)/1024:.1f} MiB")
print("FLAT yes" if max(abs(d) for d in dev) <= 0.05 else "FLAT no")
EOF
{
  echo "duration ${DURATION} s, seed $SEED, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "actions: $(for k in "${!COUNT[@]}"; do printf '%s=%s ' "$k" "${COUNT[$k]}"; done)"
  echo "views saved: $SAVES; files in the work folder: $(find "$OUT/work" -type f | wc -l)"
  echo "drops taken: $DROPS_OK ($(sort "$OUT/dropped.txt" 2>/dev/null | uniq -c | awk '{printf "%s %s, ", $2, $1}'))"
  echo "frames rendered: $FRAMES; seen: $VARIETY"
  echo "distinct error messages shown: $ERRORS"
  grep -v '^FLAT' "$OUT/memory.txt"
} | tee "$OUT/summary.txt"
cat "$OUT/rss-table.md"
if [ "$DURATION" -ge 300 ]; then
  grep -q '^FLAT yes' "$OUT/memory.txt" || fail "resident memory at the checkpoints moved by more than 5 % after the warm-up (see $OUT/rss-table.md)"
else
  log "memory not judged: a run shorter than 300 s has not finished warming up"
fi
log "PASS (logs and the memory curve in $OUT)"
