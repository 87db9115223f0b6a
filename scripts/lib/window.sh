# What the window scripts that drive one viewer share (sourced by window-tour.sh,
# window-tour-edit.sh and window-tiles.sh after scripts/lib/xvfb.sh). The caller defines
# fail and log, ROOT and BUILD, and (before starting the viewer) VIEWLOG, ERRLOG and
# VIEWER_PID.

# window_tools TOOL...: fail unless each tool is on PATH.
window_tools() {
  local tool
  for tool in "$@"; do
    command -v "$tool" >/dev/null || fail "$tool not found (scripts/window-smoke.sh --install)"
  done
}

# window_binary: the viewer to drive, in BIN: VIEWER_BIN when set, else the release
# binary (built first unless BUILD=0).
window_binary() {
  local target=${CARGO_TARGET_DIR:-$ROOT/target}
  [ -z "${VIEWER_BIN:-}" ] || BUILD=0
  if [ "$BUILD" = 1 ]; then
    log "building the release binary"
    cargo build --release -p viewer --bin viewer
  fi
  BIN=${VIEWER_BIN:-$target/release/viewer}
  [ -x "$BIN" ] || fail "$BIN not found"
}

# window_cleanup_on_exit: stop the viewer and Xvfb when the script ends, however it ends.
window_cleanup_on_exit() {
  XVFB_PID=""
  VIEWER_PID=""
  trap window_cleanup EXIT
}
window_cleanup() {
  if [ -n "$VIEWER_PID" ] && kill -0 "$VIEWER_PID" 2>/dev/null; then kill "$VIEWER_PID" || true; fi
  if [ -n "$XVFB_PID" ] && kill -0 "$XVFB_PID" 2>/dev/null; then kill "$XVFB_PID" || true; fi
}

# wait_for PATTERN TIMEOUT: until a line of the viewer's output matches (fails if the
# viewer exits or the time runs out).
wait_for() {
  local pattern=$1 timeout=$2
  local end=$((SECONDS + timeout))
  while [ $SECONDS -lt "$end" ]; do
    if grep -q -- "$pattern" "$VIEWLOG"; then return 0; fi
    kill -0 "$VIEWER_PID" 2>/dev/null || fail "viewer exited early (see $ERRLOG)"
    sleep 0.1
  done
  fail "timed out waiting for '$pattern' (see $VIEWLOG)"
}

# settle: until the viewer's output stops growing for half a second (30 s at most).
settle() {
  local n
  for _ in $(seq 1 60); do
    n=$(wc -l <"$VIEWLOG")
    sleep 0.5
    [ "$(wc -l <"$VIEWLOG")" = "$n" ] && return 0
  done
  fail "the view never settled"
}
