#!/usr/bin/env bash
# Levelling a tour scene's horizon by dragging its line, in the real viewer window under
# Xvfb, driven with xdotool (issue 30): a copy of the sample Pannellum tour
# (tests/data/tours/pannellum) opens; T turns the level-horizon mode on and
# `--print-view`'s `tour scene ... level line=x,y` names a point of the horizon line;
# the line is dragged 40 px up from there (mouse down, moves, up). The correction printed
# on release (`tour level set pitch= roll=`) must put the grabbed point of the equator
# under the release point: computed here from the courtyard's start view (yaw 20,
# pitch -5, hfov 90, rectilinear, 800x500) and Pannellum's rotation, within 1 px. Then
# Enter leaves the mode, Ctrl+Z and Ctrl+Shift+Z undo and redo it, Save writes it, and
# the saved tour.json must hold that horizonPitch/horizonRoll and pass `viewer tour
# check`. Ctrl+Q exits 0.
#
# Screenshots and logs: target/window-tour-level/. Usage: scripts/window-tour-level.sh
# [--no-build]. Honours CARGO_TARGET_DIR; VIEWER_BIN=path tests another binary (implies
# --no-build).
set -euo pipefail

cd "$(dirname "$0")/.."
ROOT=$PWD
OUT=$ROOT/target/window-tour-level
BUILD=1
for a in "$@"; do
  case $a in
    --no-build) BUILD=0 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "window-tour-level: unknown argument '$a'" >&2; exit 2 ;;
  esac
done

fail() { echo "window-tour-level: FAIL: $*" >&2; exit 1; }
log() { echo "window-tour-level: $*"; }
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
xvfb_start 171 201 "$OUT/xvfb.log"

# The position NAME=x,y on the last `tour ui` line, as "x y".
ui_xy() {
  grep '^tour ui' "$VIEWLOG" | tail -n 1 | tr ' ' '\n' | sed -n "s/^$1=//p" | tr ',' ' '
}
# The number of lines matching PATTERN so far.
count() { grep -c -- "$1" "$VIEWLOG" || true; }
# Until more than N lines match PATTERN (10 s).
wait_more() {
  for _ in $(seq 1 100); do
    [ "$(count "$1")" -gt "$2" ] && return 0
    sleep 0.1
  done
  fail "timed out waiting for another '$1' (see $VIEWLOG)"
}
key() {
  xdotool key --clearmodifiers "$1"
  sleep 0.3
}

log "the viewer on $TOUR"
: >"$VIEWLOG"
"$BIN" --size 800x500 --print-view "$TOUR" >"$VIEWLOG" 2>"$ERRLOG" &
VIEWER_PID=$!
wait_for '^tour opened .* scenes=3 problems=0' 30
wait_for '^tour arrived courtyard yaw=20.0000 pitch=-5.0000 hfov=90.0000' 60
wait_for '^tour scene courtyard 1/3 hotspots ' 30
settle
WID=$(xdotool search --sync --onlyvisible --name '^viewer' | head -n 1)
[ -n "$WID" ] || fail "no viewer window"
eval "$(xdotool getwindowgeometry --shell "$WID")"
xdotool windowfocus "$WID" 2>/dev/null || true
xdotool mousemove $((X + 700)) $((Y + 450))
sleep 0.3

# T: the level mode, its line placed.
key t
wait_for '^tour scene courtyard .* level line=' 10
settle
LINE=$(grep '^tour scene courtyard .* level line=' "$VIEWLOG" | tail -n 1 | sed 's/.* level line=//')
LX=$(printf '%.0f' "${LINE%,*}")
LY=$(printf '%.0f' "${LINE#*,}")
log "the horizon line passes $LX,$LY"
"$IMPORT" -window root "$OUT/level-on.png"

# Drag it 40 px up, in steps.
n=$(count '^tour level set')
xdotool mousemove $((X + LX)) $((Y + LY))
sleep 0.3
xdotool mousedown 1
sleep 0.2
for d in 4 8 12 16 20 24 28 32 36 40; do
  xdotool mousemove $((X + LX)) $((Y + LY - d))
  sleep 0.08
done
sleep 0.5
"$IMPORT" -window root "$OUT/level-drag.png"
xdotool mouseup 1
wait_more '^tour level set' "$n"
grep -q '^tour level grab' "$VIEWLOG" || fail "the press did not grab the line"
SET=$(grep '^tour level set' "$VIEWLOG" | tail -n 1)
P=$(tr ' ' '\n' <<<"$SET" | sed -n 's/^pitch=//p')
R=$(tr ' ' '\n' <<<"$SET" | sed -n 's/^roll=//p')
log "levelled: pitch $P roll $R"
settle
"$IMPORT" -window root "$OUT/level-set.png"

python3 - "$LX" "$LY" "$((LY - 40))" "$P" "$R" <<'PY' || fail "the grabbed point is not under the cursor"
import math, sys
lx, ly, cy, p, r = (float(a) for a in sys.argv[1:])
W, H, yaw, pitch, hfov = 800, 500, 20.0, -5.0, 90.0
f = W / 2 / math.tan(math.radians(hfov) / 2)
def ray(px, py):
    # docs/conventions.md: camera X right, Y up, Z forward; pitch about X, then yaw about Y.
    x, y, z = px - W / 2, H / 2 - py, f
    sp, cp = math.sin(math.radians(pitch)), math.cos(math.radians(pitch))
    sy, cy_ = math.sin(math.radians(yaw)), math.cos(math.radians(yaw))
    y1, z1 = y * cp + z * sp, z * cp - y * sp
    d = (x * cy_ + z1 * sy, y1, z1 * cy_ - x * sy)
    n = math.sqrt(sum(c * c for c in d))
    return tuple(c / n for c in d)
def rot(p, r, d):
    # Pannellum's horizon correction (libpannellum.js render): world d -> image direction.
    sp, cp = math.sin(math.radians(p)), math.cos(math.radians(p))
    sr, cr = math.sin(math.radians(r)), math.cos(math.radians(r))
    x, y, z = d
    return (cr * x - sr * y, sr * cp * x + cr * cp * y - sp * z, sr * sp * x + cr * sp * y + cp * z)
g = ray(lx, ly)  # the press: on the level scene's line, the equator point nearest it
lam = math.atan2(g[0], g[2])
e = (math.sin(lam), 0.0, math.cos(lam))
c = ray(lx, cy)
got = rot(p, r, c)
miss = math.sqrt(sum((a - b) ** 2 for a, b in zip(got, e))) * f
print(f"window-tour-level: the grabbed point lands {miss:.3f} px from the cursor (pitch {p}, roll {r})")
assert miss < 1.0, miss
# Dragged up near the view's centre, looking 20 degrees right of the image centre: mostly pitch.
assert p > 1.0 and abs(r) < p, (p, r)
PY

# Enter leaves the mode (the line is no longer described).
n=$(count '^tour scene courtyard')
key Return
wait_more '^tour scene courtyard' "$n"
grep '^tour scene courtyard' "$VIEWLOG" | tail -n 1 | grep -q 'level line=' && fail "Enter did not leave the level mode"
# Undo and redo the levelling.
n=$(count '^tour edit Undo')
key ctrl+z
wait_more '^tour edit Undo' "$n"
n=$(count '^tour edit Redo')
key ctrl+shift+z
wait_more '^tour edit Redo' "$n"
settle
read -r SX SY <<<"$(ui_xy save)"
[ -n "${SX:-}" ] || fail "the edit panel's Save is not placed: $(grep '^tour ui' "$VIEWLOG" | tail -n 1)"
xdotool mousemove $((X + SX)) $((Y + SY))
sleep 0.3
xdotool click 1
wait_for '^tour edit Save' 10
settle

python3 - "$TOUR" "$P" "$R" <<'PY' || fail "the saved tour lacks the horizon (see $TOUR)"
import json, sys
path, p, r = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
s = json.load(open(path))["scenes"]["courtyard"]
assert abs(s["horizonPitch"] - p) < 1e-3 and abs(s["horizonRoll"] - r) < 1e-3, s
print(f"window-tour-level: saved horizonPitch {s['horizonPitch']} horizonRoll {s['horizonRoll']}")
PY
"$BIN" tour check "$TOUR" >"$OUT/check.txt" 2>&1 || fail "tour check on the saved tour: $(cat "$OUT/check.txt")"

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
