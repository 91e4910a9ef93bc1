#!/usr/bin/env bash
# What the viewer's window and overlay cost (issue 16): the same camera path flown three ways at
# the same size, in one run, on the same adapter:
#   1. `terramp profile` (headless: render only),
#   2. `terramp view --no-overlay` (render + present into a window),
#   3. `terramp view` (render + the overlay drawn + present),
# then the medians and their ratios. The viewer's window lives on a private Xvfb server. Not a
# test: figures on a shared machine are noisy, so compare the ratios of one run.
#
#   scripts/view_cost.sh                       # nc with the trade's trees, config/paths/nc.toml
#   DATASET=data/default SETTINGS= PATH_FILE=config/paths/default.toml scripts/view_cost.sh
#
# Environment: DATASET (data/trade/nc), SETTINGS (data/trade/trees.toml; empty: none), PATH_FILE
# (config/paths/nc.toml), FRAMES (120 along the path), WIDTH × HEIGHT (1280 × 720), PRESET
# (balanced), ROUNDS (2: each way flown this many times, interleaved).
set -euo pipefail
cd "$(dirname "$0")/.."

DATASET=${DATASET:-data/trade/nc}
SETTINGS=${SETTINGS-data/trade/trees.toml}
PATH_FILE=${PATH_FILE:-config/paths/nc.toml}
FRAMES=${FRAMES:-120}
WIDTH=${WIDTH:-1280}
HEIGHT=${HEIGHT:-720}
PRESET=${PRESET:-balanced}
ROUNDS=${ROUNDS:-2}
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}

cargo build --release --bin terramp
bin=target/release/terramp
settings=()
[ -n "$SETTINGS" ] && settings=(--settings "$SETTINGS")

display=:$(( 90 + RANDOM % 100 ))
Xvfb "$display" -screen 0 "$((WIDTH + 64))x$((HEIGHT + 64))x24" -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
sleep 1

warmup=$(( FRAMES / 10 > 0 ? FRAMES / 10 : 1 ))
for round in $(seq "$ROUNDS"); do
  echo "round $round"
  "$bin" profile --dataset "$DATASET" --path "$PATH_FILE" --preset "$PRESET" "${settings[@]}" \
    --frames $(( FRAMES - warmup )) --warmup "$warmup" --width "$WIDTH" --height "$HEIGHT" \
    --json "/tmp/view_cost_profile_$round.json" >/dev/null 2>&1
  python3 - "/tmp/view_cost_profile_$round.json" <<'PY'
import json, sys
wall = json.load(open(sys.argv[1]))["totals"]["frame_wall"]
print(f"profile: {wall['samples']} frames: median {wall['median_ms']:.1f} ms, 95th percentile {wall['p95_ms']:.1f} ms per frame (headless)")
PY
  for overlay in --no-overlay ""; do
    DISPLAY=$display "$bin" view --dataset "$DATASET" --preset "$PRESET" "${settings[@]}" \
      --path "$PATH_FILE" --path-frames "$FRAMES" --quit-after-path --no-vsync \
      --width "$WIDTH" --height "$HEIGHT" $overlay 2>/dev/null | grep "^view:"
  done
done
