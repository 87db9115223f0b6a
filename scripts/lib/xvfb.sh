# The X tools and a virtual display for the window scripts (sourced by
# scripts/window-smoke.sh and scripts/window-soak.sh). The caller defines fail MESSAGE
# (exits nonzero) and log MESSAGE.

# What --install puts on a Debian/Ubuntu machine: Xvfb, xdotool, xdpyinfo/xprop,
# ImageMagick, and the X11 libraries winit loads at run time.
XVFB_PACKAGES=(xvfb xdotool x11-utils x11-apps imagemagick libx11-6 libx11-xcb1 libxcursor1
  libxi6 libxkbcommon-x11-0 libxkbcommon0 libxcb1 libxcb-xkb1)

# xvfb_install [PACKAGE...]: apt-get the X tools and any further packages (as root, else
# through sudo).
xvfb_install() {
  local sudo=""
  [ "$(id -u)" = 0 ] || sudo=sudo
  $sudo apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y "${XVFB_PACKAGES[@]}" "$@"
}

# xvfb_start FIRST LAST LOGFILE: start Xvfb (1280x800, 24 bits) on the first free display
# number in FIRST..LAST, export DISPLAY, and wait until it answers (30 s at most). Sets
# XVFB_PID (the caller's exit trap stops it).
xvfb_start() {
  local first=$1 last=$2 logfile=$3 n disp=""
  for n in $(seq "$first" "$last"); do
    if [ ! -e "/tmp/.X11-unix/X$n" ] && [ ! -e "/tmp/.X$n-lock" ]; then disp=:$n; break; fi
  done
  [ -n "$disp" ] || fail "no free X display number in $first..$last"
  log "starting Xvfb on $disp"
  Xvfb "$disp" -screen 0 1280x800x24 -nolisten tcp >"$logfile" 2>&1 &
  XVFB_PID=$!
  export DISPLAY=$disp
  for _ in $(seq 1 300); do
    xdpyinfo >/dev/null 2>&1 && return 0
    kill -0 "$XVFB_PID" 2>/dev/null || fail "Xvfb exited: $(cat "$logfile")"
    sleep 0.1
  done
  fail "Xvfb did not answer in 30 s (see $logfile)"
}
