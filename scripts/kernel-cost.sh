#!/usr/bin/env bash
# Instructions per pixel of whole LUT frames with each span kernel (callgrind; the count
# does not depend on the machine's load): 1920x1080 from the generated 8192x4096 map, a
# pan at pitch 10, hfov 90, one thread, the timed frames only. Prints a markdown table
# (the one in docs/performance.md, "Span kernels").
#
#   bash scripts/kernel-cost.sh                 # nearest, bilinear, trilinear x every kernel
#   FRAMES=4 bash scripts/kernel-cost.sh        # more frames per count (default 2)
#   VIEWS="pitch=0;pitch=80;pitch=10 hfov=150" bash scripts/kernel-cost.sh  # views, bilinear
#   KERNELS="scalar avx2" bash scripts/kernel-cost.sh  # only these kernels
#   CUBE=1 bash scripts/kernel-cost.sh          # the cube scanline renderer (2048² faces
#                                               # converted from the map), per sampler
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "kernel-cost.sh: valgrind is not installed" >&2; exit 1; }
cargo build --release -q -p lut-core --example frame_cost
bin=target/release/examples/frame_cost
frames=${FRAMES:-2}
pixels=$((1920 * 1080))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The generated map, kept between runs (generating it under valgrind takes minutes).
map_cache=${MAP_CACHE:-${TMPDIR:-/tmp}/lutpano-grid-8192x4096.raw}
[ -f "$map_cache" ] || "$bin" frames=0 cache="$map_cache" >/dev/null

# Instructions per pixel of one configuration ("key=value" arguments of frame_cost).
cost() {
  valgrind --tool=callgrind --toggle-collect='frame_cost::timed_frames' \
    --callgrind-out-file="$tmp/cg.out" "$bin" frames="$frames" threads=1 cache="$map_cache" "$@" \
    >"$tmp/log" 2>&1 || { cat "$tmp/log" >&2; exit 1; }
  local ir
  ir=$(grep -oP 'Collected : \K[0-9]+' "$tmp/log")
  awk -v ir="$ir" -v n="$((frames * pixels))" 'BEGIN { printf "%.1f", ir / n }'
}

# The kernels this machine runs under valgrind (valgrind emulates up to AVX2), or those
# of KERNELS="scalar avx2" that it runs.
kernels=()
for k in ${KERNELS:-scalar sse41 avx2}; do
  [ "$k" = scalar ] && { kernels+=(scalar); continue; }
  if valgrind -q "$bin" frames=0 map=64x32 size=64x32 kernel="$k" >/dev/null 2>&1; then
    kernels+=("$k")
  fi
done

header="|"
sep="|---|"
for k in "${kernels[@]}"; do header+=" $k |"; sep+="---:|"; done

if [ -n "${CUBE:-}" ]; then
  # The cube's faces, kept beside the map (converting under valgrind takes minutes).
  [ -f "$map_cache.cube2048" ] || "$bin" frames=0 mode=cube cache="$map_cache" >/dev/null
  echo "| cube scanline $header"
  echo "$sep"
  for s in nearest bilinear trilinear; do
    row="| $s |"
    for k in "${kernels[@]}"; do row+=" $(cost mode=cube sampler="$s" kernel="$k") |"; done
    echo "$row"
  done
  exit 0
fi

if [ -n "${VIEWS:-}" ]; then
  echo "| bilinear, view $header"
  echo "$sep"
  IFS=';' read -ra views <<<"$VIEWS"
  for v in "${views[@]}"; do
    row="| $v |"
    # shellcheck disable=SC2086 # a view is several key=value words
    for k in "${kernels[@]}"; do row+=" $(cost sampler=bilinear kernel="$k" $v) |"; done
    echo "$row"
  done
  exit 0
fi

header="| sampler $header"
echo "$header plain gather |"
echo "$sep---:|"
gather=$(cost mode=gather)
for s in nearest bilinear trilinear; do
  row="| $s |"
  for k in "${kernels[@]}"; do row+=" $(cost sampler="$s" kernel="$k") |"; done
  if [ "$s" = nearest ]; then row+=" $gather |"; else row+=" - |"; fi
  echo "$row"
done
