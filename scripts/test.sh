#!/usr/bin/env bash
# The whole test suite: formatting, lints, unit/integration/golden/property tests, the
# real window under Xvfb (a smoke test, tours, the tour editor, tiles and a one-minute
# soak), the measuring scripts on tiny sizes (scripts/peers-smoke.sh), and every fuzz
# target briefly on its committed seeds (FUZZ_SECONDS each, default 12). Works on a fresh
# machine with the Rust toolchain: it installs the Debian packages the window tests need
# when they are missing (as root, via apt-get), OpenCV for Python with pip, and the
# nightly toolchain and cargo-fuzz for the fuzz targets.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each stage line carries the minutes:seconds since the start, so a slow CI run shows where
# its time went.
stage() { printf '== [%d:%02d] %s\n' $((SECONDS / 60)) $((SECONDS % 60)) "$*"; }

need_pkgs=()
command -v Xvfb >/dev/null || need_pkgs+=(xvfb)
command -v xdotool >/dev/null || need_pkgs+=(xdotool)
[ -x /usr/bin/import ] || need_pkgs+=(imagemagick)
command -v xwininfo >/dev/null || need_pkgs+=(x11-utils)
ldconfig -p | grep -q libxkbcommon-x11 || need_pkgs+=(libxkbcommon-x11-0)
ldconfig -p | grep -q libXcursor || need_pkgs+=(libxcursor1)
ldconfig -p | grep -q libXi.so || need_pkgs+=(libxi6)
/usr/bin/python3 -c 'import Xlib' 2>/dev/null || need_pkgs+=(python3-xlib)
# The HTML report's test opens it in headless Chromium (crates/viewer/tests/report_cli.rs).
command -v chromium >/dev/null || command -v chromium-browser >/dev/null || need_pkgs+=(chromium)
# mozjpeg-sys (viewer tile's row-band JPEG reader) assembles libjpeg-turbo's SIMD with nasm.
command -v nasm >/dev/null || need_pkgs+=(nasm)
# ... and, for the aarch64 clippy pass over the viewer's binaries (when the viewer has per-architecture code), builds its C with the
# aarch64 cross compiler (the C of a -sys crate is compiled even by `cargo clippy`).
command -v aarch64-linux-gnu-gcc >/dev/null || need_pkgs+=(gcc-aarch64-linux-gnu)
if [ ${#need_pkgs[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "== installing ${need_pkgs[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq xvfb xdotool x11-utils x11-apps imagemagick \
      python3-xlib libx11-6 libx11-xcb1 libxcursor1 libxi6 libxkbcommon-x11-0 libxkbcommon0 libxcb1 \
      libxcb-xkb1 nasm gcc-aarch64-linux-gnu >/dev/null
    if [[ " ${need_pkgs[*]} " == *" chromium "* ]]; then
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null \
        || echo "warning: chromium could not be installed: the HTML report's browser test will skip LOUDLY" >&2
    fi
  else
    echo "missing packages for the window test: ${need_pkgs[*]} (install them, or run as root)" >&2
    exit 1
  fi
fi

stage "cargo fmt --check"
cargo fmt --all -- --check
cargo fmt --manifest-path fuzz/Cargo.toml -- --check
stage "cargo clippy"
cargo clippy --workspace --all-targets --profile ci -- -D warnings
stage "cargo clippy for aarch64 (the portable kernels compile warning-free off x86-64)"
if rustup target list --installed 2>/dev/null | grep -q aarch64-unknown-linux-gnu \
    || rustup target add aarch64-unknown-linux-gnu >/dev/null 2>&1; then
  cargo clippy -p lut-core --lib --target aarch64-unknown-linux-gnu -- -D warnings
  # The viewer's own code has no per-architecture code (the kernels are lut-core's); its
  # aarch64 check (every dependency checked again for aarch64, their C cross-compiled:
  # minutes of CI) runs only when that changes.
  if grep -rqE 'target_arch|target_feature' crates/viewer/src; then
    cargo clippy -p viewer --bins --target aarch64-unknown-linux-gnu -- -D warnings
  else
    echo "the viewer has no per-architecture code (grep target_arch/target_feature): its aarch64 check skipped"
  fi
else
  echo "warning: could not install the aarch64 standard library (rustup target add); aarch64 check skipped" >&2
fi
stage "cargo test (profile ci: optimized, overflow checks on)"
cargo test --workspace --profile ci
stage "cargo test again with the scalar span kernel forced (LUTPANO_KERNEL=scalar)"
# Same binaries (the kernel is chosen at run time): SIMD and scalar must render the same.
LUTPANO_KERNEL=scalar cargo test --workspace --profile ci
if [ -f scripts/window-smoke.sh ]; then
  stage "window smoke test under Xvfb"
  # the binary the test run just built (optimized, overflow checks on): no second build
  VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/window-smoke.sh
fi
stage "tour window test under Xvfb (a hotspot clicked, back and forward)"
VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/window-tour.sh
stage "tour editor window test under Xvfb (an info hotspot added at a clicked spot, saved)"
VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/window-tour-edit.sh
stage "tour horizon window test under Xvfb (the horizon line dragged, the grabbed point under the cursor, saved)"
VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/window-tour-level.sh
stage "tiled pyramid window test under Xvfb (tiles loading, coarser then sharp, the cache budget kept)"
VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/window-tiles.sh
stage "the measuring scripts' smoke test (peers.py with OpenCV and the chart redrawn; tiny sizes, numbers meaningless)"
VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/peers-smoke.sh
stage "window soak under Xvfb (one minute of random input, drops and the memory curve)"
t0=$SECONDS
VIEWER_BIN="${CARGO_TARGET_DIR:-target}/ci/viewer" bash scripts/window-soak.sh --duration 60
stage "window soak took $((SECONDS - t0)) s"
stage "fuzz targets, ${FUZZ_SECONDS:-12} s each on the committed seeds (installs nightly and cargo-fuzz if missing)"
t0=$SECONDS
bash scripts/fuzz.sh --ci --time "${FUZZ_SECONDS:-12}"
stage "fuzzing (install, build, runs) took $((SECONDS - t0)) s"
stage "all tests passed"
