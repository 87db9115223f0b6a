#!/usr/bin/env bash
# The real viewer window under Xvfb, driven as a user would with xdotool; every check
# reads what the viewer prints with --print-view (the view of each rendered frame with
# the sampler that rendered it, the panel's readouts as drawn, loads, dialogs, saves).
#
# Run 1 (settings: panel shown, zoom limit off), on a folder of three panoramas:
#   readouts true right after the load, before any input; the window title and icon;
#   an idle window renders nothing; a drag in the default (adaptive) mode renders moving
#   frames with the full-quality sampler (trilinear) and turns the right way; the wheel
#   zooms past the LUT switch; a double-click zooms in; R returns to the start view;
#   after Tab x3 the arrow keys still turn; ? shows the help; Ctrl+O opens the dialog and
#   a path typed into it loads; PageDown opens the next file in natural order; Ctrl+Q
#   exits 0 and the recent files are in the settings file.
# Run 2 (the settings written by run 1, panel hidden, default zoom limit): the panel
#   stays hidden, the view opens at 90° and the wheel reaches 50° (the zoom reach) on the
#   1024x512 sample, where a notice says why it stops; the help fits the window at
#   800x500, 640x400 and 1024x640 (resized with xdotool); a fullscreen round trip (F, the
#   window at the screen's size, Esc, back: no window manager under Xvfb) keeps hfov; the
#   recent-files menu closes on Esc; one Esc closes the Save dialog; Ctrl+S
#   saves the view where the settings say; the README's screenshot is taken here
#   (into $OUT; copied to docs/screenshot.png only with SMOKE_UPDATE_SCREENSHOT=1).
# Run 3 (panel hidden): a scene file with --show-room opens its panorama at its view with
#   its five luminaires; a click on a marker selects that light, dragging it moves it
#   along the ceiling without turning the view; dragging a room edge resizes the room, and
#   so does dragging a room corner (its two walls), Shift-dragging a ceiling or floor
#   edge changes the room's height or camera height; then, the lighting settled, a zoom
#   draws the lit panorama (lit=baked); the work plane's Em and U0 (solved on the
#   solving thread) are printed after the load and again, different, after the changes;
#   a luminaire dropped on it switches the scene's fixed exposure to automatic with a
#   notice; PageUp then opens the other panorama of the folder on its own, without the
#   scene's room and lights.
#
# Screenshots and logs: target/window-smoke/ (kept as CI artifacts). The settings live
# in a temporary config folder (LUTPANO_CONFIG_DIR), never the real home.
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
    -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
    *) echo "window-smoke: unknown argument '$a'" >&2; exit 2 ;;
  esac
done

fail() { echo "window-smoke: FAIL: $*" >&2; exit 1; }
log() { echo "window-smoke: $*"; }
# shellcheck source=scripts/lib/xvfb.sh
. scripts/lib/xvfb.sh

[ "$INSTALL" = 0 ] || xvfb_install

# /usr/local/bin/convert on some machines is a stand-in: use ImageMagick's own paths.
IMPORT=/usr/bin/import
COMPARE=/usr/bin/compare
IDENTIFY=/usr/bin/identify
for tool in Xvfb xdotool xdpyinfo xprop; do
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

XVFB_PID=""
VIEWER_PID=""
cleanup() {
  if [ -n "$VIEWER_PID" ] && kill -0 "$VIEWER_PID" 2>/dev/null; then kill "$VIEWER_PID" || true; fi
  if [ -n "$XVFB_PID" ] && kill -0 "$XVFB_PID" 2>/dev/null; then kill "$XVFB_PID" || true; fi
}
trap cleanup EXIT

xvfb_start 90 120 "$OUT/xvfb.log"

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
# Wait for the view to settle: no new line for 0.5 s, the last frame at full quality
# (a moving frame that was already full quality needs no frame after it).
settle() {
  local n
  for _ in $(seq 1 100); do
    n=$(lines)
    sleep 0.5
    if [ "$(lines)" = "$n" ] && [ "$(field level)" = full ]; then return 0; fi
  done
  fail "the view never settled"
}

CFG=$OUT/config
PANOS=$OUT/panos
SAVES=$OUT/saves
mkdir -p "$CFG" "$PANOS" "$SAVES"
# Three panoramas whose natural order (a1, a2, a10) differs from the plain one.
for n in a1 a2 a10; do cp "$ROOT/assets/courtyard.jpg" "$PANOS/$n.jpg"; done
export LUTPANO_CONFIG_DIR=$CFG

# Start the viewer with arguments "$@" (a display that answered xdpyinfo once refused
# the viewer in one run out of many: retry once).
start_viewer() {
  for attempt in 1 2; do
    "$BIN" --size 800x500 --print-view "$@" >"$VIEWLOG" 2>"$ERRLOG" &
    VIEWER_PID=$!
    sleep 1
    if kill -0 "$VIEWER_PID" 2>/dev/null || ! grep -q 'cannot open a window' "$ERRLOG"; then return 0; fi
    log "the viewer could not connect (attempt $attempt): $(cat "$ERRLOG")"
    kill -0 "$XVFB_PID" 2>/dev/null || fail "Xvfb died (see $OUT/xvfb.log)"
    sleep 1
  done
}
# No window manager gives the window the keyboard: focus it, then type through XTEST as
# a user would (held keys, so a press is not lost in one burst).
focus() {
  xdotool mousemove "$CX" "$CY"
  xdotool windowfocus "$WID" 2>/dev/null || true
  sleep 0.3
}
press() { xdotool keydown "$1"; sleep 0.1; xdotool keyup "$1"; }
chord() { xdotool keydown "$1"; sleep 0.1; xdotool key "$2"; sleep 0.1; xdotool keyup "$1"; }
find_window() {
  WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
  [ -n "$WID" ] || fail "no viewer window found"
  eval "$(xdotool getwindowgeometry --shell "$WID")"
  [ "$WIDTH" -gt 100 ] && [ "$HEIGHT" -gt 100 ] || fail "window too small: ${WIDTH}x${HEIGHT}"
}
# Close with Ctrl+Q and require a clean exit.
quit_viewer() {
  focus
  chord ctrl q
  RC=""
  for i in $(seq 1 100); do
    if [ "$i" = 50 ]; then focus; chord ctrl q; fi # one retry
    if ! kill -0 "$VIEWER_PID" 2>/dev/null; then
      set +e; wait "$VIEWER_PID"; RC=$?; set -e
      break
    fi
    sleep 0.1
  done
  [ -n "$RC" ] || fail "the viewer did not close on Ctrl+Q"
  VIEWER_PID=""
  [ "$RC" = 0 ] || fail "the viewer exited with $RC (see $ERRLOG)"
  if [ -s "$ERRLOG" ]; then log "viewer stderr:"; sed 's/^/  /' "$ERRLOG"; fi
}
# Field `name` of the last "readouts" line (the panel as drawn).
readout() { grep '^readouts ' "$VIEWLOG" | tail -n 1 | tr ';' '\n' | sed -n "s/^ *$1=//p"; }

########## Run 1: panel shown, zoom limit off ##########
printf '{"panel": true, "zoom_limit": null, "save_dir": "%s"}\n' "$SAVES" >"$CFG/settings.json"
log "run 1: the viewer on $PANOS/a1.jpg"
start_viewer "$PANOS/a1.jpg"
wait_for '^loaded ' 0 60
wait_for '^view .*fast=false' 0 60
settle
find_window
log "window $WID at ${X},${Y} size ${WIDTH}x${HEIGHT}: $(xdotool getwindowname "$WID")"
xdotool getwindowname "$WID" | grep -q '^viewer: a1.jpg (1024×512)$' ||
  fail "the title should name the file and its size: $(xdotool getwindowname "$WID")"
# The icon property may be set a moment after the window maps: poll for up to 10 s.
icon_ok=""
for _ in $(seq 100); do
  if xprop -id "$WID" _NET_WM_ICON 2>/dev/null | grep -q 'Icon (64 x 64)'; then icon_ok=1; break; fi
  sleep 0.1
done
[ -n "$icon_ok" ] || fail "no 64x64 window icon"

YAW0=$(field yaw); PITCH0=$(field pitch); HFOV0=$(field hfov); PATH0=$(field path)
SCENE=$(field size); SW=${SCENE%x*}; SH=${SCENE#*x}
log "start: yaw=$YAW0 pitch=$PITCH0 hfov=$HFOV0 $PATH0 scene ${SW}x${SH}"
CX=$((X + SW / 2)); CY=$((Y + SH / 2))
# The readouts right after the load, before any input: the table, scene and quality of
# the frame shown (not "none yet", not 0x0).
wait_for "^readouts .*in use=wide-FOV LUT.*scene=${SW}×${SH}" 0 10
log "readouts after the load: $(grep '^readouts ' "$VIEWLOG" | tail -n 1)"
[ "$(readout quality)" = "trilinear (full)" ] || fail "quality readout: $(readout quality)"
case $(readout table) in "0.0 KiB"|"") fail "table readout after the load: $(readout table)" ;; esac
$IMPORT -window root "$OUT/1-start.png"

# Idle: no frame is rendered while nothing changes.
views() { grep -c '^view ' "$VIEWLOG"; }
N=$(views)
sleep 2
[ "$(views)" = "$N" ] || fail "the idle window kept rendering ($(($(views) - N)) frames in 2 s)"
TICKS=$(awk '{print $14 + $15}' "/proc/$VIEWER_PID/stat")
sleep 2
TICKS2=$(awk '{print $14 + $15}' "/proc/$VIEWER_PID/stat")
log "idle CPU: $((TICKS2 - TICKS)) clock ticks in 2 s"
[ "$(readout fps)" = 0 ] || fail "idle fps readout: $(readout fps)"

# Drag from the scene's center 150 px to the left and 60 px up (grab style): the scene
# follows the cursor, so the view turns right (yaw grows) and down (pitch falls). In the
# default (adaptive) mode the moving frames keep the full-quality sampler while the last
# full-quality frames fit the 16 ms budget.
N=$(lines)
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
# The first-run hint was shown after the load, and the first drag took it away.
grep -q '^hint shown' "$VIEWLOG" || fail "no first-run hint on a fresh settings file"
grep -q '^hint gone' "$VIEWLOG" || fail "the first drag did not take the first-run hint away"
YAW1=$(field yaw); PITCH1=$(field pitch)
log "after drag: yaw=$YAW1 pitch=$PITCH1"
$IMPORT -window root "$OUT/2-dragged.png"
awk -v a="$YAW0" -v b="$YAW1" 'BEGIN { exit !(b > a + 5) }' ||
  fail "dragging left should turn right: yaw $YAW0 -> $YAW1"
awk -v a="$PITCH0" -v b="$PITCH1" 'BEGIN { exit !(b < a - 1) }' ||
  fail "dragging up should look down: pitch $PITCH0 -> $PITCH1"
MOVING=$(tail -n +"$((N + 1))" "$VIEWLOG" | grep '^view .*fast=true' || true)
log "moving frames by sampler and level: $(echo "$MOVING" | grep -o 'sampler=[a-z]* level=[a-z-]*' | sort | uniq -c | tr '\n' ';')"
echo "$MOVING" | grep -q 'sampler=trilinear level=full fast=true' ||
  fail "no moving frame was rendered at full quality (see $VIEWLOG)"

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
DIFF=$($COMPARE -metric AE "$OUT/1-start.png" "$OUT/3-zoomed.png" "$OUT/diff.png" 2>&1 >/dev/null || true)
DIFF=${DIFF%% *}
log "pixels changed: $DIFF"
awk -v d="$DIFF" -v n="$((SW * SH))" 'BEGIN { exit !(d + 0 > n / 4) }' ||
  fail "the screenshots barely differ ($DIFF pixels)"

# Double-click: zoom in twice toward the point.
xdotool mousemove "$((CX + 100))" "$((CY - 50))"
sleep 0.2
xdotool click --repeat 2 --delay 80 1
settle
HFOV2=$(field hfov)
log "after double-click: hfov=$HFOV2"
awk -v a="$HFOV1" -v b="$HFOV2" 'BEGIN { exit !(b < a * 0.55 && b > a * 0.45) }' ||
  fail "a double-click should halve hfov: $HFOV1 -> $HFOV2"

# R returns to the file's start view (no GPano: yaw 0, pitch 0, hfov 90).
focus
press r
settle
log "after R: yaw=$(field yaw) pitch=$(field pitch) hfov=$(field hfov)"
[ "$(field yaw)" = 0.0000 ] && [ "$(field pitch)" = 0.0000 ] && [ "$(field hfov)" = 90.0000 ] ||
  fail "R should return to yaw 0, pitch 0, hfov 90"

# The keyboard trap: Tab x3 puts egui's focus on a button; the arrows still turn, at
# no more frames than the display refreshes.
for _ in 1 2 3; do press Tab; sleep 0.1; done
HZ=$(sed -n 's/^refresh \([0-9]*\).*/\1/p' "$VIEWLOG" | head -n 1)
N=$(views)
xdotool keydown Right; sleep 1; xdotool keyup Right
settle
FRAMES=$(($(views) - N))
log "after Tab x3 and Right held 1 s: yaw=$(field yaw), $FRAMES frames at ${HZ} Hz"
awk -v b="$(field yaw)" 'BEGIN { exit !(b > 5) }' || fail "after Tab x3 the arrow keys no longer turn"
[ "$FRAMES" -le $((HZ * 13 / 10 + 5)) ] || fail "$FRAMES frames for 1 s of turning at ${HZ} Hz"

# ? shows the help overlay (and hides it again).
N=$(lines)
xdotool key question
wait_for '^help shown' "$N" 5
sleep 0.3
$IMPORT -window root "$OUT/4-help.png"
xdotool key question
wait_for '^help hidden' "$N" 5

# L glides into the little planet (stereographic, pitch -90, hfov 300) and back to the
# view it left; V cycles the projections; E shows the error heat map with its max in the
# readouts (the LUT's sampling error: within the 0.05 px budget).
BEFORE="$(field yaw) $(field pitch) $(field hfov)"
N=$(views)
press l
settle
log "after L: proj=$(field proj) pitch=$(field pitch) hfov=$(field hfov), $(($(views) - N)) frames"
[ "$(field proj)" = stereographic ] && [ "$(field pitch)" = -90.0000 ] && [ "$(field hfov)" = 300.0000 ] ||
  fail "L should show the little planet (stereographic, pitch -90, hfov 300)"
[ $(($(views) - N)) -ge 5 ] || fail "the little planet should be an animated transition"
$IMPORT -window root "$OUT/4-planet.png"
press l
settle
[ "$(field proj)" = rectilinear ] && [ "$(field yaw) $(field pitch) $(field hfov)" = "$BEFORE" ] ||
  fail "L again should return to $BEFORE (rectilinear), not $(field yaw) $(field pitch) $(field hfov) $(field proj)"
for want in stereographic fisheye equisolid pannini rectilinear; do
  press v
  settle
  [ "$(field proj)" = "$want" ] || fail "V should switch to $want, not $(field proj)"
done
N=$(lines)
press e
wait_for "^readouts .*error max=" "$N" 10
HEAT=$(readout 'error max' | sed 's/ px//')
log "heat map: error max $HEAT px"
awk -v e="$HEAT" 'BEGIN { exit !(e >= 0 && e <= 0.05) }' || fail "heat map max $HEAT px is not within 0.05"
$IMPORT -window root "$OUT/4-heat.png"
press e
settle

# Ctrl+O opens the dialog; / edits its path; the typed file loads.
N=$(lines)
chord ctrl o
wait_for "^dialog open $PANOS" "$N" 5
sleep 0.5
press slash
sleep 0.3
xdotool type --delay 40 "/a2.jpg"
sleep 0.3
$IMPORT -window root "$OUT/5-dialog.png"
press Return
wait_for "^dialog picked $PANOS/a2.jpg" "$N" 10
wait_for "^loaded $PANOS/a2.jpg" "$N" 30
settle
wait_for "^readouts .*in use=wide-FOV LUT.*scene=${SW}×${SH}" "$N" 10
log "opened from the dialog: $(grep '^loaded ' "$VIEWLOG" | tail -n 1)"

# PageDown: the next file in natural order (a2 -> a10).
N=$(lines)
focus
press Next
wait_for "^loaded $PANOS/a10.jpg" "$N" 30
settle
log "after PageDown: $(grep '^loaded ' "$VIEWLOG" | tail -n 1)"
$IMPORT -window root "$OUT/6-next.png"
quit_viewer
for n in a1 a2 a10; do
  grep -q "\"$PANOS/$n.jpg\"" "$CFG/settings.json" || fail "$n.jpg is not among the recent files"
done
grep -q '"first_run_hint": false' "$CFG/settings.json" || fail "the first-run hint is not remembered as shown"

########## Run 2: the settings of run 1, panel hidden, default zoom limit ##########
# Edited as JSON (the file is written with its keys sorted, so a line-wise delete of the
# last key would leave a trailing comma and an unreadable file).
python3 - "$CFG/settings.json" <<'PY'
import json, sys
p = sys.argv[1]
s = json.load(open(p))
s["panel"] = False
s.pop("zoom_limit", None)
json.dump(s, open(p, "w"), indent=2)
PY
log "run 2: the viewer on the bundled sample"
start_viewer
wait_for '^loaded ' 0 60
wait_for '^view .*fast=false' 0 60
settle
find_window
SCENE=$(field size); SW=${SCENE%x*}; SH=${SCENE#*x}
CX=$((X + SW / 2)); CY=$((Y + SH / 2))
[ "$SW" = "$WIDTH" ] || fail "the panel should stay hidden: scene ${SW} of ${WIDTH} px"
! grep -q '^readouts ' "$VIEWLOG" || fail "readouts printed with the panel hidden"
! grep -q '^hint shown' "$VIEWLOG" || fail "the first-run hint came back on the second run"
# The bundled 1024x512 sample: the default zoom limit (one map pixel over two screen
# pixels) would stop at ~102° in an 800-px scene, but zooming in always reaches the zoom
# reach (50°), where it stops with a notice saying why and where to change it.
log "start: hfov=$(field hfov)"
[ "$(field hfov)" = 90.0000 ] || fail "the view should open at the default 90°, not $(field hfov)"
N=$(lines)
xdotool mousemove "$CX" "$CY"
for _ in $(seq 1 10); do xdotool click 4; sleep 0.1; done
settle
log "after scroll: hfov=$(field hfov)"
[ "$(field hfov)" = 50.0000 ] || fail "the wheel should reach 50° on a 1024x512 map, got $(field hfov)"
wait_for '^notice zoom stops at 50°: .*Zoom limit' "$N" 5
log "$(grep '^notice zoom stops' "$VIEWLOG" | tail -n 1)"
sleep 0.3
$IMPORT -window root -crop "${WIDTH}x${HEIGHT}+${X}+${Y}" +repage "$OUT/screenshot.png"
if [ "${SMOKE_UPDATE_SCREENSHOT:-0}" = 1 ]; then cp "$OUT/screenshot.png" "$ROOT/docs/screenshot.png"; fi

# The help fits the window at 800x500, 640x400 (the smallest supported) and 1024x640 (the
# default): the viewer prints where egui laid it out against the scene.
help_fits() {
  local line
  line=$(grep '^help rect ' "$VIEWLOG" | tail -n 1)
  log "$1: $line"
  echo "$line" | awk -F'[ ,]' '{ exit !($3 >= $8 && $4 >= $9 && $5 <= $10 && $6 <= $11 && $5 - $3 > ($10 - $8) / 2) }' ||
    fail "the help does not fit the ${1} window: $line"
}
resize_to() {
  local n
  n=$(lines)
  xdotool windowsize "$WID" "$1" "$2"
  wait_for "^view .*size=${1}x${2} " "$n" 10
  settle
}
N=$(lines)
focus
xdotool key question
wait_for '^help rect ' "$N" 5
help_fits 800x500
for size in "640 400" "1024 640"; do
  N=$(lines)
  # shellcheck disable=SC2086 # width and height
  resize_to $size
  wait_for "^help rect .* scene 0,0,${size% *},${size#* }" "$N" 5
  help_fits "${size/ /x}"
done
$IMPORT -window root -crop "1024x640+${X}+${Y}" +repage "$OUT/help-1024x640.png"
N=$(lines)
xdotool key question
wait_for '^help hidden' "$N" 5
# A fullscreen round trip keeps the view's hfov. Under Xvfb there is no window manager to
# honour F, so the window's size change that fullscreen makes is done by hand (the whole
# screen and back); F and Esc are pressed too, as a user would.
resize_to 800 500
HFOVF=$(field hfov)
focus
press f
sleep 0.3
resize_to 1280 800
log "fullscreen-sized: hfov=$(field hfov)"
press Escape
sleep 0.3
resize_to 800 500
log "fullscreen round trip: hfov $HFOVF -> $(field hfov)"
[ "$(field hfov)" = "$HFOVF" ] || fail "the fullscreen round trip changed hfov: $HFOVF -> $(field hfov)"

# The recent-files menu (the toolbar's ⏷, after Open) closes on Esc.
N=$(lines)
xdotool mousemove "$((X + 88))" "$((Y + 22))"; sleep 0.2; xdotool click 1
wait_for '^menu open' "$N" 5
$IMPORT -window root -crop "${WIDTH}x${HEIGHT}+${X}+${Y}" +repage "$OUT/recent.png"
xdotool windowfocus "$WID" 2>/dev/null || true
press Escape
wait_for '^menu closed' "$N" 5
# One Esc closes the Save dialog, whose file name field has the keyboard.
N=$(lines)
focus
chord ctrl s
wait_for "^dialog save $SAVES" "$N" 5
sleep 0.5
press Escape
wait_for '^dialog closed' "$N" 5
sleep 0.3

# Ctrl+S: the Save dialog opens in the folder of the settings, Enter saves view-1.png.
N=$(lines)
focus
chord ctrl s
wait_for "^dialog save $SAVES" "$N" 5
sleep 0.5
press Return
wait_for "^saved $SAVES/view-1.png (${SW}×${SH})" "$N" 20
[ "$($IDENTIFY -format '%wx%h' "$SAVES/view-1.png")" = "${SW}x${SH}" ] || fail "view-1.png is not ${SW}x${SH}"
quit_viewer

########## Run 3: a scene file, its room shown, a luminaire picked and dragged ##########
log "run 3: the viewer on assets/interior_lit.json with --show-room"
start_viewer --scene "$ROOT/assets/interior_lit.json" --show-room --pitch 70
wait_for '^loaded .*interior.jpg' 0 60
wait_for '^markers ' 0 60
settle
find_window
SCENE=$(field size); SW=${SCENE%x*}; SH=${SCENE#*x}
CX=$((X + SW / 2)); CY=$((Y + SH / 2))
[ "$(field yaw)" = -40.0000 ] || fail "the scene's view yaw -40 should be kept, got $(field yaw)"
[ "$(field lights)" = 5 ] || fail "the scene's five lights should be loaded, got $(field lights)"
# The work plane's figures arrive from the solving thread (inter-reflections included).
wait_for '^work-plane Em ' 0 60
WP1=$(grep '^work-plane Em ' "$VIEWLOG" | tail -n 1)
WPN=$(lines)
log "$WP1"
# A marker well inside the scene (clear of the toolbar): "N=X,Y".
MARK=$(grep '^markers ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | grep '=' |
  awk -F'[=,]' -v w="$SW" -v h="$SH" '$2 > 60 && $2 < w - 60 && $3 > 80 && $3 < h - 60 { print; exit }')
[ -n "$MARK" ] || fail "no luminaire marker inside the view: $(grep '^markers ' "$VIEWLOG" | tail -n 1)"
LN=${MARK%%=*}; MXY=${MARK#*=}; MX=$((X + ${MXY%,*})); MY=$((Y + ${MXY#*,}))
log "light $LN's marker at $MX,$MY"
N=$(lines)
xdotool mousemove "$MX" "$MY"; sleep 0.2; xdotool click 1
wait_for "^light $LN selected" "$N" 5
settle
YAW0=$(field yaw); PITCH0=$(field pitch)
# Drag the marker: the light moves along the ceiling, the view does not turn.
N=$(lines)
xdotool mousemove "$MX" "$MY"; sleep 0.2; xdotool mousedown 1; sleep 0.1
for i in 1 2 3 4 5 6 7 8; do xdotool mousemove $((MX + 8 * i)) $((MY + 5 * i)); sleep 0.05; done
sleep 0.2; xdotool mouseup 1
wait_for "^light $LN moved to " "$N" 5
settle
MOVED=$(grep "^light $LN moved to " "$VIEWLOG" | tail -n 1)
log "$MOVED"
[ "$(echo "$MOVED" | sed 's/.* to //' | cut -d, -f2)" = 2.680 ] ||
  fail "a ceiling light should stay 2.680 m up: $MOVED"
[ "$(field yaw)" = "$YAW0" ] && [ "$(field pitch)" = "$PITCH0" ] ||
  fail "dragging a light turned the view: yaw $YAW0 -> $(field yaw), pitch $PITCH0 -> $(field pitch)"
# Drag a room edge (its middle, clear of the toolbar): the room changes, the view does not.
EDGE=$(grep '^edges ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | grep '=' |
  awk -F'[=,]' -v w="$SW" -v h="$SH" '$2 > 60 && $2 < w - 60 && $3 > 80 && $3 < h - 60 { print; exit }')
[ -n "$EDGE" ] || fail "no room edge inside the view: $(grep '^edges ' "$VIEWLOG" | tail -n 1)"
EXY=${EDGE#*=}; EX=$((X + ${EXY%,*})); EY=$((Y + ${EXY#*,}))
log "room edge ${EDGE%%=*} at $EX,$EY"
N=$(lines)
xdotool mousemove "$EX" "$EY"; sleep 0.2; xdotool mousedown 1; sleep 0.1
for i in 1 2 3 4 5 6; do xdotool mousemove $((EX - 4 * i)) $((EY + 6 * i)); sleep 0.05; done
sleep 0.2; xdotool mouseup 1
wait_for "^room " "$N" 5
settle
log "$(grep '^room ' "$VIEWLOG" | tail -n 1)"
grep -q '^room 4.170x2.990x2.700 centre 0.485,0.045' "$VIEWLOG" &&
  fail "dragging a room edge left the room as it was"
[ "$(field yaw)" = "$YAW0" ] && [ "$(field pitch)" = "$PITCH0" ] ||
  fail "dragging a room edge turned the view"
# Drag a room corner (clear of the toolbar): both its walls move, the view does not turn.
settle
ROOM0=$(grep '^room ' "$VIEWLOG" | tail -n 1)
CORNER=$(grep '^corners ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | grep '=' |
  awk -F'[=,]' -v w="$SW" -v h="$SH" '$2 > 60 && $2 < w - 60 && $3 > 80 && $3 < h - 60 { print; exit }')
[ -n "$CORNER" ] || fail "no room corner inside the view: $(grep '^corners ' "$VIEWLOG" | tail -n 1)"
{
  KXY=${CORNER#*=}; KX=$((X + ${KXY%,*})); KY=$((Y + ${KXY#*,}))
  log "room corner ${CORNER%%=*} at $KX,$KY"
  N=$(lines)
  xdotool mousemove "$KX" "$KY"; sleep 0.2; xdotool mousedown 1; sleep 0.1
  for i in 1 2 3 4 5 6; do xdotool mousemove $((KX + 5 * i)) $((KY - 3 * i)); sleep 0.05; done
  sleep 0.2; xdotool mouseup 1
  wait_for "^room " "$N" 5
  settle
  ROOM1=$(grep '^room ' "$VIEWLOG" | tail -n 1)
  log "$ROOM1"
  [ "$ROOM1" != "$ROOM0" ] || fail "dragging a room corner left the room as it was: $ROOM1"
  [ "$(field yaw)" = "$YAW0" ] && [ "$(field pitch)" = "$PITCH0" ] ||
    fail "dragging a room corner turned the view"
}
# Shift-drag a floor or ceiling edge (Room::EDGES 0-3 and 8-11) up or down: the room's
# height or camera height changes, its walls and the view stay.
settle
ROOM1=$(grep '^room ' "$VIEWLOG" | tail -n 1)
LEVEL=$(grep '^edges ' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | grep '=' |
  awk -F'[=,]' -v w="$SW" -v h="$SH" '($1 < 4 || $1 > 7) && $2 > 60 && $2 < w - 60 && $3 > 80 && $3 < h - 60 { print; exit }')
[ -n "$LEVEL" ] || fail "no floor or ceiling edge inside the view: $(grep '^edges ' "$VIEWLOG" | tail -n 1)"
LXY=${LEVEL#*=}; LX=$((X + ${LXY%,*})); LY=$((Y + ${LXY#*,}))
log "level edge ${LEVEL%%=*} at $LX,$LY (Shift)"
N=$(lines)
# (Keys reach the window only with the keyboard focus: no window manager gives it.)
xdotool windowfocus "$WID" 2>/dev/null || true
xdotool mousemove "$LX" "$LY"; sleep 0.2; xdotool keydown Shift_L; sleep 0.1
xdotool mousedown 1; sleep 0.1
for i in 1 2 3 4 5 6; do xdotool mousemove "$LX" $((LY - 5 * i)); sleep 0.05; done
sleep 0.2; xdotool mouseup 1; sleep 0.1; xdotool keyup Shift_L
wait_for "^room " "$N" 5
settle
ROOM2=$(grep '^room ' "$VIEWLOG" | tail -n 1)
log "$ROOM2"
[ "$ROOM2" != "$ROOM1" ] || fail "Shift-dragging a floor or ceiling edge left the room as it was: $ROOM2"
[ "$(echo "$ROOM2" | cut -d' ' -f3-4)" = "$(echo "$ROOM1" | cut -d' ' -f3-4)" ] ||
  fail "Shift-dragging a level moved the walls: $ROOM1 -> $ROOM2"
[ "$(echo "$ROOM2" | cut -d' ' -f2 | cut -dx -f1-2)" = "$(echo "$ROOM1" | cut -d' ' -f2 | cut -dx -f1-2)" ] ||
  fail "Shift-dragging a level changed the width or depth: $ROOM1 -> $ROOM2"
[ "$(field yaw)" = "$YAW0" ] && [ "$(field pitch)" = "$PITCH0" ] ||
  fail "Shift-dragging a level turned the view"
# The room and a light were dragged (each frame lit from the illuminance map); now the
# lighting has settled: the panorama is lit once and a zoom draws the lit copy.
N=$(lines)
xdotool mousemove "$CX" "$CY"; sleep 0.2; xdotool click 4
wait_for '^view .* lit=baked' "$N" 10
settle
log "after the lighting settled: lit=$(field lit)"
# The figures followed the dragged light and room: fresh ones, not the first.
wait_for '^work-plane Em ' "$WPN" 30
WP2=$(grep '^work-plane Em ' "$VIEWLOG" | tail -n 1)
log "$WP2"
[ "$WP2" != "$WP1" ] || fail "the work plane's figures did not follow the changes: $WP1"
sleep 0.3
$IMPORT -window root -crop "${WIDTH}x${HEIGHT}+${X}+${Y}" +repage "$OUT/lights.png"
# A luminaire dropped on the lit scene, whose exposure the scene file fixes: the exposure
# follows the lights from then on (a notice says so and how to fix it again), so the
# picture is not blown out: the 5 % of the room's surface above the exposure at most.
N=$(lines)
timeout 20 /usr/bin/python3 scripts/xdnd-drop.py "$WID" "$ROOT/tests/data/ldt/office_louvre_2x28w.ldt" ||
  fail "the window did not take the dropped luminaire"
wait_for '^notice exposure now follows the lights' "$N" 10
wait_for '^view .* lights=6 ' "$N" 10
settle
log "after the drop: lights=$(field lights); $(grep '^notice exposure' "$VIEWLOG" | tail -n 1)"
$IMPORT -window root -crop "${WIDTH}x${HEIGHT}+${X}+${Y}" +repage "$OUT/dropped.png"
MEAN=$($IDENTIFY -format '%[fx:mean]' "$OUT/dropped.png")
log "mean brightness after the drop: $MEAN"
awk -v m="$MEAN" 'BEGIN { exit !(m > 0.05 && m < 0.8) }' || fail "the picture after the drop is not readable (mean $MEAN)"
# PageUp opens the folder's other panorama on its own: the scene's room and lights go.
N=$(lines)
focus
press Prior
wait_for "^loaded .*courtyard.jpg" "$N" 30
settle
log "after PageUp: $(grep '^loaded ' "$VIEWLOG" | tail -n 1), lights=$(field lights)"
[ "$(field lights)" = 0 ] || fail "a panorama opened on its own kept the scene's $(field lights) lights"
quit_viewer
log "PASS (screenshots in $OUT$([ "${SMOKE_UPDATE_SCREENSHOT:-0}" = 1 ] && echo ", docs/screenshot.png updated"))"
