#!/usr/bin/env bash
# Issue 47's counts (docs/PERFORMANCE.md, "Counts in every profile"): what each pass asks of the
# GPU per frame (draws, indirect draws, dispatches, triangles submitted, vertex, clipped-triangle,
# fragment and compute invocations, bytes uploaded and read back) in `terramp profile` over the
# demo's dataset with the demo's generated trees, at 1920 × 1080 balanced. The counts are exact
# and the same on every adapter with pipeline statistics (lavapipe's invocations are llvmpipe's:
# whole 4 × 4 blocks of fragments); the times beside them are this machine's.
#
#   scripts/counts.sh                        # prints the table from its seeds on
#   COUNT_FRAGMENTS=true scripts/counts.sh   # with `gpu.count_fragments` (each frame waited for)
#
# Environment: COUNT_FRAGMENTS (false), FRAMES (8), WARMUP (4), WIDTH × HEIGHT (1920 × 1080), DATA (data/default) and
# IMPOSTORS (data/impostors), as `terramp demo` makes them; OUT (out/counts: the settings and the
# JSON). Needs the release build.
set -euo pipefail
cd "$(dirname "$0")/.."
FRAMES=${FRAMES:-8}
WARMUP=${WARMUP:-4}
WIDTH=${WIDTH:-1920}
HEIGHT=${HEIGHT:-1080}
DATA=${DATA:-data/default}
IMPOSTORS=${IMPOSTORS:-data/impostors}
OUT=${OUT:-out/counts}
COUNT_FRAGMENTS=${COUNT_FRAGMENTS:-false}
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
bin=${CARGO_TARGET_DIR:-target}/release/terramp
[ -x "$bin" ] || { echo "no $bin: cargo build --release" >&2; exit 1; }
for d in "$DATA" "$IMPOSTORS"; do
  [ -d "$d" ] || { echo "no $d: terramp demo makes it" >&2; exit 1; }
done
mkdir -p "$OUT"
settings="$OUT/settings.toml"
printf '[gpu]\ncount_fragments = %s\n[seeds]\nclass_table = "nc-generated"\n[draw_seeds]\nimpostors = "%s"\n' \
  "$COUNT_FRAGMENTS" "$(realpath "$IMPOSTORS")" >"$settings"
"$bin" profile --dataset "$DATA" --frames "$FRAMES" --warmup "$WARMUP" --width "$WIDTH" --height "$HEIGHT" \
  --settings "$settings" --json "$OUT/profile.json" 2>/dev/null | sed -n '/^Seeds checked/,$p'
