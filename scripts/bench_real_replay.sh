#!/usr/bin/env bash
# Replays real captures with framelab and with gfxrecon-replay, in turn, on the same device, and
# prints per-frame times after the first and whole-process times side by side:
#
#   scripts/bench_real_replay.sh target/release/framelab [RUNS]
#
# gfxrecon-replay presents to a window: run it under X (Xvfb :99 -screen 0 1280x720x24 and
# DISPLAY=:99 on a machine without one), or set GFXR_WSI=headless where the driver has
# VK_EXT_headless_surface. Per frame after the first: gfxrecon-replay's own
# `--measurement-frame-range 2-4` on the whole three-frame vkcube capture (frames 2 and 3);
# framelab's wall time for 41 replays of the imported frames less that for 1, over 40 (each
# replay runs the capture's three frames, so the figure is divided by three as well). Whole
# process, for every trimmed real capture in tests/fixtures/gfxr: `gfxrecon-replay FILE` (state
# restored, the frame replayed and presented) against `framelab replay CAPTURE --frames 1` of
# the frame imported once beforehand (resources created and filled, the frame replayed and its
# targets read back). FRAMELAB_BENCH_ONLY="a b" limits the trimmed captures to those named.
set -euo pipefail
bin="$(realpath "$1")"
runs="${2:-5}"
cd "$(dirname "$0")/.."
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fixtures=tests/fixtures/gfxr
"$bin" import "$fixtures/vkcube_whole.gfxr" -o "$work/whole.json" >/dev/null 2>&1
"$bin" import "$fixtures/vkd3d_gears_f2.gfxr" -o "$work/gears.json" >/dev/null 2>&1

wall() { # seconds of wall time of a command, to the microsecond
  local start end
  start="$(date +%s%N)"
  "$@" >/dev/null 2>&1
  end="$(date +%s%N)"
  awk -v a="$start" -v b="$end" 'BEGIN {printf "%.6f\n", (b - a) / 1e9}'
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

wsi=(--wsi "${GFXR_WSI:-xlib}")
gx=() fl=() gw=() fw=()
for _ in $(seq "$runs"); do
  gx+=("$(gfxrecon-replay "${wsi[@]}" --measurement-frame-range 2-4 "$fixtures/vkcube_whole.gfxr" 2>&1 |
    sed -n 's/.*fps, \([0-9.]*\) seconds, 2 frames.*/\1/p' | awk '{print $1 / 2 * 1000}')")
  one="$(wall "$bin" replay "$work/whole.json" --frames 1 --quiet)"
  many="$(wall "$bin" replay "$work/whole.json" --frames 41 --quiet)"
  fl+=("$(awk -v a="$one" -v b="$many" 'BEGIN {print (b - a) / 40 / 3 * 1000}')")
  gw+=("$(wall gfxrecon-replay "${wsi[@]}" "$fixtures/vkd3d_gears_f2.gfxr")")
  fw+=("$(wall "$bin" replay "$work/gears.json" --frames 1 --quiet)")
done
g="$(printf '%s\n' "${gx[@]}" | median)"
f="$(printf '%s\n' "${fl[@]}" | median)"
echo "vkcube (whole run), ms per frame after the first: gfxrecon-replay $g, framelab $f, framelab/gfxrecon-replay $(awk -v a="$f" -v b="$g" 'BEGIN {printf "%.2f", a / b}')"
g="$(printf '%s\n' "${gw[@]}" | median)"
f="$(printf '%s\n' "${fw[@]}" | median)"
echo "vkd3d-gears (trimmed), s for the whole process: gfxrecon-replay $g, framelab $f, framelab/gfxrecon-replay $(awk -v a="$f" -v b="$g" 'BEGIN {printf "%.2f", a / b}')"

trimmed=(${FRAMELAB_BENCH_ONLY:-vkcube_f3 vkcubepp_f3 vkd3d_triangle_f1 vkd3d_gears_f2 mpv_testsrc_f5 mpv_testsrc2_f30 qtquick_f30 qt6quick_f30 gtk4_f30 gstreamer_f30 mangohud_f30 vkbasalt_f100 warzone_menu_f120})
echo
echo "| capture | gfxrecon-replay, s | framelab, s | framelab / gfxrecon-replay |"
echo "| --- | --- | --- | --- |"
for name in "${trimmed[@]}"; do
  "$bin" import "$fixtures/$name.gfxr" -o "$work/$name.json" >/dev/null 2>&1
  gw=() fw=()
  for _ in $(seq "$runs"); do
    gw+=("$(wall gfxrecon-replay "${wsi[@]}" "$fixtures/$name.gfxr")")
    fw+=("$(wall "$bin" replay "$work/$name.json" --frames 1 --quiet)")
  done
  g="$(printf '%s\n' "${gw[@]}" | median)"
  f="$(printf '%s\n' "${fw[@]}" | median)"
  echo "| \`$name\` | $g | $f | $(awk -v a="$f" -v b="$g" 'BEGIN {printf "%.2f", a / b}') |"
done
