#!/usr/bin/env bash
# A tour in the real viewer window under Xvfb, driven with xdotool (issue 30): the sample
# Pannellum tour (tests/data/tours/pannellum/tour.json) opens in its first scene at its
# start view with its hotspot markers drawn where `--print-view` says they are (the
# screenshot's pixel there is the marker's colour); a click on the "Into the room" link
# lands in the target scene at the view the link names (sameAzimuth: 20 + 30 - 120 = -70,
# targetPitch 0, the scene's hfov 100) and the title names it; Alt+Left goes back to the
# courtyard at the view it was left at; the mouse's forward button goes forward again;
# Ctrl+Q exits 0.
#
# Screenshots and logs: target/window-tour/. Usage: scripts/window-tour.sh [--no-build]
# Honours CARGO_TARGET_DIR; VIEWER_BIN=path tests another binary (implies --no-build).
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/window-tour
BUILD=1
for a in "$@"; do
  case $a in
    --no-build) BUILD=0 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "window-tour: unknown argument '$a'" >&2; exit 2 ;;
  esac
done

fail() { echo "window-tour: FAIL: $*" >&2; exit 1; }
log() { echo "window-tour: $*"; }
# shellcheck source=scripts/lib/xvfb.sh
. scripts/lib/xvfb.sh
# shellcheck source=scripts/lib/window.sh
. scripts/lib/window.sh

IMPORT=/usr/bin/import
window_tools Xvfb xdotool xdpyinfo
[ -x "$IMPORT" ] || fail "$IMPORT not found (ImageMagick)"

window_binary

rm -rf "$OUT"
mkdir -p "$OUT/config"
VIEWLOG=$OUT/viewer.stdout
ERRLOG=$OUT/viewer.stderr
export LUTPANO_CONFIG_DIR=$OUT/config
printf '{"panel": false, "zoom_limit": null}\n' >"$OUT/config/settings.json"

window_cleanup_on_exit
xvfb_start 130 160 "$OUT/xvfb.log"

count() { grep -c -- "$1" "$VIEWLOG" || true; }
# Wait until the pattern has matched more than `n` lines.
wait_more() {
  local pattern=$1 n=$2 timeout=$3
  local end=$((SECONDS + timeout))
  while [ $SECONDS -lt "$end" ]; do
    [ "$(count "$pattern")" -gt "$n" ] && return 0
    kill -0 "$VIEWER_PID" 2>/dev/null || fail "viewer exited early (see $ERRLOG)"
    sleep 0.1
  done
  fail "timed out waiting for another '$pattern' (see $VIEWLOG)"
}
field() { grep '^view ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | sed -n "s/^$1=//p"; }
# The last "tour scene" line's position of hotspot $1: "x y" (rounded).
hotspot_xy() {
  grep '^tour scene ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | sed -n "s/^$1@//p" |
    awk -F, '{ printf "%d %d\n", $1 + 0.5, $2 + 0.5 }'
}
# The screen's pixel at (x, y) as "r,g,b" (0-255).
pixel() {
  "$IMPORT" -window root -crop "1x1+$1+$2" txt:- 2>/dev/null | tail -n 1 |
    sed -n 's/.*(\([0-9]*\),\([0-9]*\),\([0-9]*\).*/\1,\2,\3/p'
}
# The view is at yaw/pitch/hfov within 0.01 degrees.
view_is() {
  awk -v y="$(field yaw)" -v p="$(field pitch)" -v h="$(field hfov)" \
    -v Y="$1" -v P="$2" -v H="$3" 'BEGIN {
      d = y - Y; while (d > 180) d -= 360; while (d < -180) d += 360;
      exit !(d * d < 1e-4 && (p - P) ^ 2 < 1e-4 && (h - H) ^ 2 < 1e-4) }'
}

TOUR=$ROOT/tests/data/tours/pannellum/tour.json
log "the viewer on $TOUR"
"$BIN" --size 800x500 --print-view "$TOUR" >"$VIEWLOG" 2>"$ERRLOG" &
VIEWER_PID=$!
wait_for '^tour opened .* scenes=3 problems=0' 30
wait_for '^tour arrived courtyard yaw=20.0000 pitch=-5.0000 hfov=90.0000' 60
wait_for '^tour scene courtyard 1/3 hotspots ' 30
settle
view_is 20 -5 90 || fail "the courtyard's start view is yaw 20 pitch -5 hfov 90: $(grep '^view ' "$VIEWLOG" | tail -n 1)"
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
[ -n "$WID" ] || fail "no viewer window"
eval "$(xdotool getwindowgeometry --shell "$WID")"
NAME=$(xdotool getwindowname "$WID")
log "window at $X,$Y: $NAME"
case $NAME in *"tour.json: Courtyard"*) ;; *) fail "the title should name the tour and scene: $NAME" ;; esac

read -r HX HY <<<"$(hotspot_xy 0)"
[ -n "${HX:-}" ] || fail "hotspot 0 is not in view: $(grep '^tour scene ' "$VIEWLOG" | tail -n 1)"
log "hotspot 0 (to the interior) at $HX,$HY"
"$IMPORT" -window root "$OUT/courtyard.png"
# The marker's fill (markers::SCENE_COLOR, 0xFFB000) at its centre.
[ "$(pixel $((X + HX)) $((Y + HY)))" = "255,176,0" ] ||
  fail "no scene marker at $HX,$HY: pixel $(pixel $((X + HX)) $((Y + HY)))"

# Click the link: it glides, then the interior arrives at the link's view.
xdotool mousemove $((X + HX)) $((Y + HY))
sleep 0.3
xdotool click 1
wait_for '^tour click courtyard hotspot 0' 10
wait_for '^tour arrived interior yaw=-70.0000 pitch=0.0000 hfov=100.0000' 30
wait_for '^tour scene interior 2/3' 30
settle
view_is -70 0 100 || fail "the interior should show yaw -70 pitch 0 hfov 100: $(grep '^view ' "$VIEWLOG" | tail -n 1)"
NAME=$(xdotool getwindowname "$WID")
case $NAME in *"tour.json: Interior"*) ;; *) fail "the title should name the interior: $NAME" ;; esac
"$IMPORT" -window root "$OUT/interior.png"
log "landed in the interior: $NAME"

# Alt+Left: back to the courtyard at the view it was left at.
xdotool mousemove $((X + 400)) $((Y + 450))
xdotool windowfocus "$WID" 2>/dev/null || true
sleep 0.3
n=$(count '^tour arrived courtyard')
xdotool keydown alt; sleep 0.1; xdotool key Left; sleep 0.1; xdotool keyup alt
wait_more '^tour arrived courtyard yaw=20.0000 pitch=-5.0000 hfov=90.0000' "$n" 30
log "Alt+Left: back in the courtyard"
# The mouse's forward button (X button 9): the interior again.
n=$(count '^tour arrived interior')
sleep 1.5
xdotool click 9
wait_more '^tour arrived interior yaw=-70.0000' "$n" 30
log "forward button: the interior again"

xdotool keydown ctrl; sleep 0.1; xdotool key q; sleep 0.1; xdotool keyup ctrl
RC=""
for _ in $(seq 1 100); do
  if ! kill -0 "$VIEWER_PID" 2>/dev/null; then
    set +e; wait "$VIEWER_PID"; RC=$?; set -e
    break
  fi
  sleep 0.1
done
[ -n "$RC" ] || fail "the viewer did not close on Ctrl+Q"
VIEWER_PID=""
[ "$RC" = 0 ] || fail "the viewer exited with $RC (see $ERRLOG)"
log "PASS"
