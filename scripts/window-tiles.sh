#!/usr/bin/env bash
# A tiled pyramid in the real viewer window under Xvfb (issue 29): `viewer tile
# --synthetic` writes a small pyramid (64-px tiles, so a view needs many), the window opens
# its folder with --cache-mib 64 and the panel shown; the checks read what the viewer
# prints with --print-view:
#   the title names the tiled pyramid; the panel's readouts show the tiled path, the level
#   drawn and the cache at 64 MiB; zoomed in, a frame is drawn coarser while tiles decode
#   (the quality readout says so, the indicator shows the count pending: screenshot) and
#   the view gets sharp; Ctrl+Q exits 0 with the budget in the settings file; a second run
#   without --cache-mib keeps the 64 MiB.
# Screenshots and logs: target/window-tiles/. Settings in a temporary config folder.
#
# Usage: scripts/window-tiles.sh [--no-build]   (VIEWER_BIN=path tests another binary)
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/window-tiles
BUILD=1
for a in "$@"; do
  case $a in
    --no-build) BUILD=0 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "window-tiles: unknown argument '$a'" >&2; exit 2 ;;
  esac
done
fail() { echo "window-tiles: FAIL: $*" >&2; exit 1; }
log() { echo "window-tiles: $*"; }
# shellcheck source=scripts/lib/xvfb.sh
. scripts/lib/xvfb.sh
# shellcheck source=scripts/lib/window.sh
. scripts/lib/window.sh
window_tools Xvfb xdotool xdpyinfo
window_binary

rm -rf "$OUT"
mkdir -p "$OUT/config"
VIEWLOG=$OUT/viewer.stdout
ERRLOG=$OUT/viewer.stderr
window_cleanup_on_exit
xvfb_start 121 150 "$OUT/xvfb.log"
export LUTPANO_CONFIG_DIR=$OUT/config

PYR=$OUT/pyramid
log "writing a synthetic pyramid"
"$BIN" tile --synthetic 4096x2048 --tile-size 64 -q -o "$PYR"

start_viewer() {
  : >"$VIEWLOG"
  "$BIN" --size 800x500 --print-view "$@" >"$VIEWLOG" 2>"$ERRLOG" &
  VIEWER_PID=$!
}
quit_viewer() {
  local wid=$1 rc=""
  xdotool windowfocus "$wid" 2>/dev/null || true
  sleep 0.3
  xdotool keydown ctrl; sleep 0.1; xdotool key q; sleep 0.1; xdotool keyup ctrl
  for _ in $(seq 1 100); do
    if ! kill -0 "$VIEWER_PID" 2>/dev/null; then
      set +e; wait "$VIEWER_PID"; rc=$?; set -e
      break
    fi
    sleep 0.1
  done
  [ -n "$rc" ] || fail "the viewer did not close on Ctrl+Q"
  VIEWER_PID=""
  [ "$rc" = 0 ] || fail "the viewer exited with $rc (see $ERRLOG)"
}

########## Run 1: --cache-mib 64, panel shown ##########
printf '{"panel": true}\n' >"$OUT/config/settings.json"
log "run 1: the window on $PYR"
start_viewer "$PYR" --cache-mib 64 --hfov 90
wait_for '^readouts .*in use=tiled pyramid' 60
wait_for '^readouts .*tile cache=.* of 64 MiB' 20
wait_for '^readouts .*tile level=' 5
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
[ -n "$WID" ] || fail "no viewer window found"
TITLE=$(xdotool getwindowname "$WID")
echo "$TITLE" | grep -q 'tiled pyramid' || fail "title: $TITLE"
# Zoom in fast (keys), so the view needs tiles of the top levels not yet decoded.
xdotool windowfocus "$WID" 2>/dev/null || true
eval "$(xdotool getwindowgeometry --shell "$WID")"
xdotool mousemove $((X + 200)) $((Y + 250))
for _ in $(seq 1 12); do xdotool click 4; done
wait_for '^readouts .*coarser than wanted' 30
/usr/bin/import -window root "$OUT/loading.png" 2>/dev/null || true
log "drawn coarser while tiles decode: $(grep '^readouts .*coarser than wanted' "$VIEWLOG" | tail -n 1 | tr ';' '\n' | grep -E 'quality|tiles=' | tr '\n' ' ')"
# Then sharp: a later frame not coarser.
n=$(grep -n '^readouts .*coarser than wanted' "$VIEWLOG" | tail -n 1 | cut -d: -f1)
end=$((SECONDS + 60))
until tail -n +"$((n + 1))" "$VIEWLOG" | grep '^readouts ' | grep -v 'coarser than wanted' | grep -q 'in use=tiled pyramid;'; do
  [ $SECONDS -lt $end ] || fail "never sharp after zooming in (see $VIEWLOG)"
  kill -0 "$VIEWER_PID" 2>/dev/null || fail "viewer exited early (see $ERRLOG)"
  sleep 0.2
done
log "sharp: $(grep '^readouts ' "$VIEWLOG" | tail -n 1 | tr ';' '\n' | grep -E 'tile' | tr '\n' ' ')"
quit_viewer "$WID"
grep -q '"tile_cache_mib": 64' "$OUT/config/settings.json" ||
  fail "the budget is not in the settings: $(cat "$OUT/config/settings.json")"

########## Run 2: the budget from the settings ##########
log "run 2: no --cache-mib"
start_viewer "$PYR/config.json"
wait_for '^readouts .*tile cache=.* of 64 MiB' 60
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
quit_viewer "$WID"
log "passed"
