#!/usr/bin/env bash
# Smoke test of the real viewer window under Xvfb.
#
# Starts the release binary on the bundled sample in a virtual X display, takes a
# screenshot, drags with the mouse, scrolls the wheel, takes another, checks that the
# view changed in the expected direction (from the view the viewer prints with
# --print-view), checks that an idle window renders nothing, resets with R, closes the
# window with Ctrl+Q and requires exit code 0.
#
# Screenshots and logs: target/window-smoke/. Also writes docs/screenshot.png.
#
# Usage: scripts/window-smoke.sh [--install] [--no-build]
#   --install   apt-get the X tools first (xvfb xdotool x11-utils x11-apps imagemagick and
#               the X11 runtime libraries); otherwise nothing is installed.
#   --no-build  use the existing release binary.
# Honours CARGO_TARGET_DIR; VIEWER_BIN=path tests another binary (implies --no-build).
# Exits nonzero on any failure.
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/window-smoke
INSTALL=0
BUILD=1
for a in "$@"; do
  case $a in
    --install) INSTALL=1 ;;
    --no-build) BUILD=0 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "window-smoke: unknown argument '$a'" >&2; exit 2 ;;
  esac
done

fail() { echo "window-smoke: FAIL: $*" >&2; exit 1; }
log() { echo "window-smoke: $*"; }

if [ "$INSTALL" = 1 ]; then
  SUDO=""
  [ "$(id -u)" = 0 ] || SUDO=sudo
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y xvfb xdotool x11-utils x11-apps \
    imagemagick libx11-6 libx11-xcb1 libxcursor1 libxi6 libxkbcommon-x11-0 libxkbcommon0 \
    libxcb1 libxcb-xkb1
fi

# /usr/local/bin/convert on some machines is a stand-in: use ImageMagick's own paths.
IMPORT=/usr/bin/import
COMPARE=/usr/bin/compare
for tool in Xvfb xdotool xdpyinfo; do
  command -v "$tool" >/dev/null || fail "$tool not found (run with --install)"
done
[ -x "$IMPORT" ] || fail "$IMPORT not found (ImageMagick; run with --install)"
[ -x "$COMPARE" ] || fail "$COMPARE not found (ImageMagick; run with --install)"

TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
[ -z "${VIEWER_BIN:-}" ] || BUILD=0
if [ "$BUILD" = 1 ]; then
  log "building the release binary"
  cargo build --release -p viewer --bin viewer
fi
BIN=${VIEWER_BIN:-$TARGET/release/viewer}
[ -x "$BIN" ] || fail "$BIN not found"

rm -rf "$OUT"
mkdir -p "$OUT"
VIEWLOG=$OUT/viewer.stdout
ERRLOG=$OUT/viewer.stderr

# A free display number.
DISP=""
for n in $(seq 90 120); do
  if [ ! -e /tmp/.X11-unix/X$n ] && [ ! -e /tmp/.X$n-lock ]; then DISP=:$n; break; fi
done
[ -n "$DISP" ] || fail "no free X display number"

XVFB_PID=""
VIEWER_PID=""
cleanup() {
  if [ -n "$VIEWER_PID" ] && kill -0 "$VIEWER_PID" 2>/dev/null; then kill "$VIEWER_PID" || true; fi
  if [ -n "$XVFB_PID" ] && kill -0 "$XVFB_PID" 2>/dev/null; then kill "$XVFB_PID" || true; fi
}
trap cleanup EXIT

log "starting Xvfb on $DISP"
Xvfb "$DISP" -screen 0 1280x800x24 -nolisten tcp >"$OUT/xvfb.log" 2>&1 &
XVFB_PID=$!
export DISPLAY=$DISP
for _ in $(seq 1 100); do
  xdpyinfo >/dev/null 2>&1 && break
  sleep 0.1
done
xdpyinfo >/dev/null 2>&1 || fail "Xvfb did not start (see $OUT/xvfb.log)"

# Wait until `pattern` appears in the viewer's stdout after line `from` (timeout seconds).
wait_for() {
  local pattern=$1 from=$2 timeout=$3
  local end=$((SECONDS + timeout))
  while [ $SECONDS -lt "$end" ]; do
    if tail -n +"$((from + 1))" "$VIEWLOG" | grep -q -- "$pattern"; then return 0; fi
    kill -0 "$VIEWER_PID" 2>/dev/null || fail "viewer exited early (see $ERRLOG)"
    sleep 0.1
  done
  fail "timed out waiting for '$pattern' (see $VIEWLOG)"
}
lines() { wc -l <"$VIEWLOG"; }
# Field `name` of the last "view" line, e.g. field yaw.
field() { grep '^view ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | sed -n "s/^$1=//p"; }
# Wait for the view to settle: a full-quality frame and then no new frame for 0.5 s.
settle() {
  local n
  for _ in $(seq 1 100); do
    n=$(lines)
    sleep 0.5
    if [ "$(lines)" = "$n" ] && [ "$(field fast)" = false ]; then return 0; fi
  done
  fail "the view never settled"
}

log "starting the viewer on the bundled sample"
for attempt in 1 2; do
  "$BIN" --size 800x500 --print-view >"$VIEWLOG" 2>"$ERRLOG" &
  VIEWER_PID=$!
  sleep 1
  # A display that answered xdpyinfo once refused the viewer in one run out of many:
  # retry once, then give up (the message is in $ERRLOG).
  if kill -0 "$VIEWER_PID" 2>/dev/null || ! grep -q 'cannot open a window' "$ERRLOG"; then break; fi
  log "the viewer could not connect (attempt $attempt): $(cat "$ERRLOG")"
  kill -0 "$XVFB_PID" 2>/dev/null || fail "Xvfb died (see $OUT/xvfb.log)"
  sleep 1
done
wait_for '^loaded ' 0 60
wait_for '^view .*fast=false' 0 60
settle
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
[ -n "$WID" ] || fail "no viewer window found"
eval "$(xdotool getwindowgeometry --shell "$WID")"
log "window $WID at ${X},${Y} size ${WIDTH}x${HEIGHT}"
[ "$WIDTH" -gt 100 ] && [ "$HEIGHT" -gt 100 ] || fail "window too small: ${WIDTH}x${HEIGHT}"

YAW0=$(field yaw); PITCH0=$(field pitch); HFOV0=$(field hfov); PATH0=$(field path)
SCENE=$(field size); SW=${SCENE%x*}; SH=${SCENE#*x}
log "start: yaw=$YAW0 pitch=$PITCH0 hfov=$HFOV0 $PATH0 scene ${SW}x${SH}"
$IMPORT -window root "$OUT/1-start.png"

# Idle: no frame is rendered while nothing changes.
N=$(lines)
sleep 2
[ "$(lines)" = "$N" ] || fail "the idle window kept rendering ($(($(lines) - N)) frames in 2 s)"
TICKS=$(awk '{print $14 + $15}' "/proc/$VIEWER_PID/stat")
sleep 2
TICKS2=$(awk '{print $14 + $15}' "/proc/$VIEWER_PID/stat")
log "idle CPU: $((TICKS2 - TICKS)) clock ticks in 2 s"

# Drag from the scene's center 150 px to the left and 60 px up (grab style): the scene
# follows the cursor, so the view turns right (yaw grows) and down (pitch falls).
CX=$((X + SW / 2)); CY=$((Y + SH / 2))
xdotool mousemove "$CX" "$CY"
sleep 0.2
xdotool mousedown 1
for i in $(seq 1 15); do
  xdotool mousemove "$((CX - 10 * i))" "$((CY - 4 * i))"
  sleep 0.03
done
sleep 0.3 # hold still before release: no inertia throw
xdotool mouseup 1
settle
YAW1=$(field yaw); PITCH1=$(field pitch)
log "after drag: yaw=$YAW1 pitch=$PITCH1"
$IMPORT -window root "$OUT/2-dragged.png"
awk -v a="$YAW0" -v b="$YAW1" 'BEGIN { exit !(b > a + 5) }' ||
  fail "dragging left should turn right: yaw $YAW0 -> $YAW1"
awk -v a="$PITCH0" -v b="$PITCH1" 'BEGIN { exit !(b < a - 1) }' ||
  fail "dragging up should look down: pitch $PITCH0 -> $PITCH1"

# Scroll up (away from the user) five notches at the scene center: zoom in past 60°,
# which switches from the wide-FOV to the high-resolution LUT.
xdotool mousemove "$CX" "$CY"
for _ in 1 2 3 4 5; do
  xdotool click 4
  sleep 0.1
done
settle
HFOV1=$(field hfov); PATH1=$(field path)
log "after scroll: hfov=$HFOV1 $PATH1"
$IMPORT -window root "$OUT/3-zoomed.png"
awk -v a="$HFOV0" -v b="$HFOV1" 'BEGIN { exit !(b < a && b < 60) }' ||
  fail "scrolling up should zoom in below 60°: hfov $HFOV0 -> $HFOV1"
[ "$PATH0" = LutWide ] || fail "at hfov $HFOV0 the wide LUT should be in use, got $PATH0"
[ "$PATH1" = LutHigh ] || fail "at hfov $HFOV1 the high-resolution LUT should be in use, got $PATH1"

# The picture changed between the screenshots.
DIFF=$($COMPARE -metric AE "$OUT/1-start.png" "$OUT/3-zoomed.png" "$OUT/diff.png" 2>&1 >/dev/null || true)
DIFF=${DIFF%% *}
log "pixels changed: $DIFF"
awk -v d="$DIFF" -v n="$((SW * SH))" 'BEGIN { exit !(d + 0 > n / 4) }' ||
  fail "the screenshots barely differ ($DIFF pixels)"

# No window manager gives the window the keyboard: focus it, then type through XTEST as
# a user would (held keys, so a press is not lost in one burst).
focus() {
  xdotool mousemove "$CX" "$CY"
  xdotool windowfocus "$WID" 2>/dev/null || true
  sleep 0.3
}

# R resets the view (the paper's RESIZE). The README screenshot is taken now, with the
# tables warm, so its render time is a typical one.
focus
xdotool keydown r; sleep 0.1; xdotool keyup r
settle
log "after R: yaw=$(field yaw) pitch=$(field pitch) hfov=$(field hfov)"
[ "$(field yaw)" = 0.0000 ] && [ "$(field pitch)" = 0.0000 ] && [ "$(field hfov)" = 90.0000 ] ||
  fail "R should reset the view to yaw 0, pitch 0, hfov 90"
sleep 0.3 # the readouts' follow-up frame
$IMPORT -window root "$OUT/4-reset.png"
$IMPORT -window root -crop "${WIDTH}x${HEIGHT}+${X}+${Y}" +repage "$ROOT/docs/screenshot.png"

# Close with Ctrl+Q and require a clean exit.
close_keys() {
  focus
  xdotool keydown ctrl; sleep 0.1; xdotool key q; sleep 0.1; xdotool keyup ctrl
}
close_keys
RC=""
for i in $(seq 1 100); do
  [ "$i" != 50 ] || close_keys # one retry
  if ! kill -0 "$VIEWER_PID" 2>/dev/null; then
    set +e; wait "$VIEWER_PID"; RC=$?; set -e
    break
  fi
  sleep 0.1
done
[ -n "$RC" ] || fail "the viewer did not close on Ctrl+Q"
VIEWER_PID=""
[ "$RC" = 0 ] || fail "the viewer exited with $RC (see $ERRLOG)"
if [ -s "$ERRLOG" ]; then
  log "viewer stderr:"; sed 's/^/  /' "$ERRLOG"
fi
log "PASS (screenshots in $OUT, docs/screenshot.png updated)"
