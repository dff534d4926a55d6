#!/usr/bin/env bash
# Records what a `framelab` binary prints and writes on the bundled captures, the invalid corpus,
# the GFXReconstruct samples and the timing fixtures, one file per output, so two builds can be
# compared byte for byte (timings aside):
#
#   scripts/outputs.sh OLD-BINARY /tmp/before
#   scripts/outputs.sh target/release/framelab /tmp/after
#   diff -r /tmp/before /tmp/after
#
# Each command's stdout, stderr (with the binary's own path removed) and exit code are kept.
# Replays export at a small scale; their manifests and image checksums are kept, their timing
# files are not (GPU times differ from run to run). The inspector's screenshots show live
# timings, so they are compared by the kittest snapshots' metric instead (`cargo test`).
set -uo pipefail
bin="$(realpath "$1")"
out="$2"
cd "$(dirname "$0")/.."
rm -rf "$out"
mkdir -p "$out"
samples="${GFXR_SAMPLES:-../shared/gfxr-samples}"

# run NAME ARGS...: stdout, stderr and exit code of one command
run() {
  local name="$1"
  shift
  "$bin" "$@" >"$out/$name.stdout" 2>"$out/$name.stderr"
  echo $? >"$out/$name.rc"
  sed -i "s|$bin|framelab|g" "$out/$name.stderr"
}

captures=(captures/example/frame.json captures/example/frame_sync.json
  captures/night_city/main_street_day.json captures/night_city/river_bank_night.json
  tests/fixtures/minimal.json tests/fixtures/culling.json tests/fixtures/cycle.json
  tests/fixtures/replay_kinds/kinds.json)
for c in "${captures[@]}"; do
  n="$(echo "$c" | tr '/' '_')"
  run "validate_$n" validate "$c"
  run "validate_json_$n" validate "$c" --json
  run "info_$n" info "$c"
  run "info_json_$n" info "$c" --json
  run "info_half_$n" info "$c" --json --scale 0.5
  run "analyze_$n" analyze "$c"
  run "analyze_json_$n" analyze "$c" --json
  run "analyze_cull_$n" analyze "$c" --json --cull
  run "graph_dot_$n" graph "$c"
  run "graph_json_$n" graph "$c" --json
done
for c in tests/invalid/*.json; do
  n="$(basename "$c" .json)"
  run "invalid_$n" validate "$c"
  run "invalid_json_$n" validate "$c" --json
done
run structure_example diff captures/example/frame.json captures/example/frame_sync.json --structure --json
run structure_night diff captures/night_city/main_street_day.json captures/night_city/river_bank_night.json --structure
run structure_night_md diff captures/night_city/main_street_day.json captures/night_city/river_bank_night.json --structure --markdown
run diff_ab diff tests/fixtures/timing/a.json tests/fixtures/timing/b.json --json
run diff_ab_text diff tests/fixtures/timing/a.json tests/fixtures/timing/b.json
run diff_example diff tests/fixtures/timing/example_a.json tests/fixtures/timing/example_b.json --json
run diff_example_md diff tests/fixtures/timing/example_a.json tests/fixtures/timing/example_b.json --markdown
run schema schema

tmp="$(mktemp -d)"
for s in tests/fixtures/gfxr/*.jsonl "$samples"/*.jsonl "$samples"/*.gfxr "$samples"/*.rdc; do
  [ -f "$s" ] || continue
  n="import_$(basename "$s" | tr '.' '_')"
  run "$n" import "$s" -o "$tmp/$n.json" --json
  sed -i "s|$tmp|TMP|g" "$out/$n.stdout" "$out/$n.stderr"
  if [ -f "$tmp/$n.json" ]; then
    cp "$tmp/$n.json" "$out/$n.capture.json"
    run "${n}_analyze" analyze "$tmp/$n.json" --json
    sed -i "s|$tmp|TMP|g" "$out/${n}_analyze.stdout" "$out/${n}_analyze.stderr"
  fi
done

# Replays: the export manifest and a checksum of every file written.
for c in captures/example/frame.json tests/fixtures/replay_kinds/kinds.json captures/night_city/main_street_day.json; do
  n="replay_$(echo "$c" | tr '/' '_')"
  scale=0.25
  run "$n" replay "$c" --scale "$scale" --frames 2 --quiet --out "$tmp/$n"
  sed -i "s|$tmp|TMP|g" "$out/$n.stdout" "$out/$n.stderr"
  # The printed timings change from run to run.
  rm -f "$out/$n.stdout"
  if [ -d "$tmp/$n" ]; then
    cp "$tmp/$n/manifest.json" "$out/$n.manifest.json"
    (cd "$tmp/$n" && find . -type f ! -name manifest.json -print0 | sort -z | xargs -0 sha256sum) >"$out/$n.sha256"
  fi
done
run replay_after replay captures/example/frame.json --scale 0.25 --quiet --after bloom_extract --out "$tmp/after"
rm -f "$out/replay_after.stdout"
[ -d "$tmp/after" ] && (cd "$tmp/after" && find . -type f -print0 | sort -z | xargs -0 sha256sum) >"$out/replay_after.sha256"

rm -rf "$tmp"
echo "outputs of $bin in $out: $(ls "$out" | wc -l) files"
