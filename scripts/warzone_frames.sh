#!/usr/bin/env bash
# Captures Warzone 2100 (Debian `warzone2100`, Vulkan backend) on whatever Vulkan device is
# here, under Xvfb, and checks that framelab replays each frame to the image
# `gfxrecon-replay --screenshot-all` shows for it:
#
#   scripts/warzone_frames.sh target/release/framelab [OUT_DIR]
#
# Three frames: the main menu (frame 120) and a moment of an unattended skirmish on each of
# two maps, Sk-HighGround (`--skirmish=highground.json --autogame`) and the maze of the game's
# own `miza.json` test (`--skirmish=miza.json --autogame`), frame 120 of each: about 50 frames
# into play. The in-play capture is 49 MB, too large for the repository (the menu is there as
# `tests/fixtures/gfxr/warzone_menu_f120.gfxr`); on lavapipe with two cores the skirmish takes
# about six minutes to reach its frame. Prints, per frame, the pixels that differ and those
# that differ by more than 16 of 255 in some channel, and exits non-zero past the replay
# tolerance (more than 0.5% of pixels off by more than 16).
set -euo pipefail
bin="$(realpath "$1")"
out="$(realpath -m "${2:-$(mktemp -d)}")"
mkdir -p "$out/cfg"
display=":77"
Xvfb "$display" -screen 0 1024x768x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
sleep 2
export DISPLAY="$display"

capture() { # name, then warzone's extra arguments
  local name="$1"
  shift
  (
    export VK_INSTANCE_LAYERS=VK_LAYER_LUNARG_gfxreconstruct
    export GFXRECON_CAPTURE_FILE="$out/$name.gfxr"
    export GFXRECON_CAPTURE_FRAMES=120
    export GFXRECON_CAPTURE_FILE_TIMESTAMP=false
    export GFXRECON_PAGE_GUARD_ALIGN_BUFFER_SIZES=true
    exec /usr/games/warzone2100 --gfxbackend=vulkan --resolution=854x480 --window --nosound \
      --configdir="$out/cfg" "$@"
  ) >"$out/$name.log" 2>&1 &
  local game=$!
  local file="$out/${name}_frame_120.gfxr"
  for _ in $(seq 1 900); do
    grep -q "Finished recording graphics API capture" "$out/$name.log" 2>/dev/null && break
    kill -0 "$game" 2>/dev/null || break
    sleep 1
  done
  kill -9 "$game" 2>/dev/null || true
  wait "$game" 2>/dev/null || true
  [ -s "$file" ] || { echo "$name: no capture (see $out/$name.log)" >&2; return 1; }
}

check() { # name
  local name="$1" file="$out/${1}_frame_120.gfxr"
  mkdir -p "$out/ref_$name"
  gfxrecon-replay --screenshot-all --screenshot-dir "$out/ref_$name" "$file" >/dev/null 2>&1
  convert "$out/ref_$name"/screenshot_frame_*.bmp -alpha off "$out/$name.ref.png"
  "$bin" import "$file" -o "$out/$name.json"
  "$bin" replay "$out/$name.json" --frames 1 --out "$out/${name}_out" --quiet
  local presented
  presented=$(python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); print(next(f["file"] for f in m["files"] if f.get("presented")))' "$out/${name}_out/manifest.json")
  convert "$out/${name}_out/$presented" -alpha off "$out/$name.replayed.png"
  local off far pixels
  off=$(compare -metric AE "$out/$name.replayed.png" "$out/$name.ref.png" null: 2>&1 || true)
  far=$(compare -metric AE -fuzz 6.3% "$out/$name.replayed.png" "$out/$name.ref.png" null: 2>&1 || true)
  pixels=$((854 * 480))
  echo "$name: $off of $pixels pixels differ, $far by more than 16/255"
  [ "$((far * 200))" -le "$pixels" ]
}

capture menu
capture play --skirmish=highground.json --autogame
capture play_miza --skirmish=miza.json --autogame
status=0
check menu || status=1
check play || status=1
check play_miza || status=1
exit "$status"
