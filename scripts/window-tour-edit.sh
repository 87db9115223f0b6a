#!/usr/bin/env bash
# The tour editor in the real viewer window under Xvfb, driven with xdotool (issue 30): a
# copy of the sample Pannellum tour (tests/data/tours/pannellum) opens; the Edit toggle is
# clicked where `--print-view`'s `tour ui` line says it is; a click on the scene picks a
# spot (`tour edit spot yaw=.. pitch=..`); text is typed into the edit panel's text field,
# "Add info" and "Save" are clicked; the saved tour.json must hold one more hotspot in the
# courtyard, an info hotspot with that text at the spot's yaw and pitch (within 0.01°),
# and still read as a tour (`viewer tour check`). Ctrl+Q exits 0.
#
# Screenshots and logs: target/window-tour-edit/. Usage: scripts/window-tour-edit.sh
# [--no-build]. Honours CARGO_TARGET_DIR; VIEWER_BIN=path tests another binary (implies
# --no-build).
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/window-tour-edit
BUILD=1
for a in "$@"; do
  case $a in
    --no-build) BUILD=0 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "window-tour-edit: unknown argument '$a'" >&2; exit 2 ;;
  esac
done

fail() { echo "window-tour-edit: FAIL: $*" >&2; exit 1; }
log() { echo "window-tour-edit: $*"; }
# shellcheck source=scripts/lib/xvfb.sh
. scripts/lib/xvfb.sh
# shellcheck source=scripts/lib/window.sh
. scripts/lib/window.sh

IMPORT=/usr/bin/import
window_tools Xvfb xdotool xdpyinfo python3
[ -x "$IMPORT" ] || fail "$IMPORT not found (ImageMagick)"

window_binary

rm -rf "$OUT"
mkdir -p "$OUT/config"
# The tour is edited and saved in a copy, never in tests/data.
cp -r "$ROOT/tests/data/tours/pannellum" "$OUT/tour"
TOUR=$OUT/tour/tour.json
VIEWLOG=$OUT/viewer.stdout
ERRLOG=$OUT/viewer.stderr
export LUTPANO_CONFIG_DIR=$OUT/config
printf '{"panel": false, "zoom_limit": null}\n' >"$OUT/config/settings.json"

window_cleanup_on_exit
xvfb_start 170 200 "$OUT/xvfb.log"

# The position NAME=x,y on the last `tour ui` line, as "x y".
ui_xy() {
  grep '^tour ui' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | sed -n "s/^$1=//p" | tr ',' ' '
}
# Click window point (x, y).
click_at() {
  xdotool mousemove $((X + $1)) $((Y + $2))
  sleep 0.3
  xdotool click 1
  sleep 0.3
}

log "the viewer on $TOUR"
: >"$VIEWLOG"
"$BIN" --size 800x500 --print-view "$TOUR" >"$VIEWLOG" 2>"$ERRLOG" &
VIEWER_PID=$!
wait_for '^tour opened .* scenes=3 problems=0' 30
wait_for '^tour arrived courtyard' 60
wait_for '^tour scene courtyard 1/3 hotspots ' 30
wait_for '^tour ui edit=' 30
settle
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
[ -n "$WID" ] || fail "no viewer window"
eval "$(xdotool getwindowgeometry --shell "$WID")"
xdotool windowfocus "$WID" 2>/dev/null || true
BEFORE=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["scenes"]["courtyard"]["hotSpots"]))' "$TOUR")

# The Edit toggle: the panel opens and its controls are placed.
read -r EX EY <<<"$(ui_xy edit)"
log "Edit toggle at $EX,$EY"
click_at "$EX" "$EY"
wait_for '^tour ui edit=.* save=' 10
settle
read -r TX TY <<<"$(ui_xy text)"
read -r AX AY <<<"$(ui_xy add-info)"
read -r SX SY <<<"$(ui_xy save)"
[ -n "${SX:-}" ] && [ -n "${AX:-}" ] && [ -n "${TX:-}" ] || fail "the edit panel's controls are not placed: $(grep '^tour ui' "$VIEWLOG" | tail -n 1)"
log "text field at $TX,$TY, Add info at $AX,$AY, Save at $SX,$SY"
"$IMPORT" -window root "$OUT/panel.png"

# A spot on the scene, right of and below the panel, away from every marker.
PX=640 PY=400
NEAR=$(grep '^tour scene courtyard' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | sed -n 's/^[0-9]*@//p' |
  awk -F, -v X="$PX" -v Y="$PY" '($1 - X) ^ 2 + ($2 - Y) ^ 2 < 40 ^ 2 { print $1 "," $2 }')
[ -z "$NEAR" ] || fail "a marker is at $NEAR, too near the spot $PX,$PY"
n=$(grep -c '^tour edit spot' "$VIEWLOG" || true)
click_at "$PX" "$PY"
for _ in $(seq 1 50); do
  [ "$(grep -c '^tour edit spot' "$VIEWLOG" || true)" -gt "$n" ] && break
  sleep 0.1
done
SPOT=$(grep '^tour edit spot' "$VIEWLOG" | tail -n 1)
case $SPOT in *"yaw="*"selected=None"*) ;; *) fail "the click should pick a spot, no hotspot: ${SPOT:-nothing printed}" ;; esac
SYAW=$(tr ' ' '\n' <<<"$SPOT" | sed -n 's/^yaw=//p')
SPITCH=$(tr ' ' '\n' <<<"$SPOT" | sed -n 's/^pitch=//p')
log "spot yaw $SYAW pitch $SPITCH"
# The panel's rows move when the spot's line changes: placed again.
settle
read -r TX TY <<<"$(ui_xy text)"
read -r AX AY <<<"$(ui_xy add-info)"
read -r SX SY <<<"$(ui_xy save)"
log "now text field at $TX,$TY, Add info at $AX,$AY, Save at $SX,$SY"

# Typed only once the text field has the keyboard (else the keys would be the viewer's).
TEXT="Added under Xvfb"
click_at "$TX" "$TY"
wait_for '^tour ui .* typing$' 10
xdotool type --delay 40 "$TEXT"
sleep 0.5
click_at "$AX" "$AY"
wait_for '^tour edit AddInfo' 10
settle
"$IMPORT" -window root "$OUT/added.png"
click_at "$SX" "$SY"
wait_for '^tour edit Save' 10
settle

python3 - "$TOUR" "$BEFORE" "$TEXT" "$SYAW" "$SPITCH" <<'PY' || fail "the saved tour lacks the hotspot (see $TOUR)"
import json, sys
path, before, text, yaw, pitch = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
hs = json.load(open(path))["scenes"]["courtyard"]["hotSpots"]
assert len(hs) == before + 1, f"{len(hs)} hotspots, {before} before"
h = hs[-1]
assert h.get("type") == "info", h
assert h.get("text") == text, h
d = (h["yaw"] - yaw + 180) % 360 - 180
assert abs(d) < 0.01 and abs(h["pitch"] - pitch) < 0.01, (h, yaw, pitch)
print(f"window-tour-edit: saved: {h}")
PY
"$BIN" tour check "$TOUR" >"$OUT/check.txt" 2>&1 || fail "tour check on the saved tour: $(cat "$OUT/check.txt")"

xdotool mousemove $((X + 400)) $((Y + 450))
sleep 0.3
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
