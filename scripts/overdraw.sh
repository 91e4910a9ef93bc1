#!/usr/bin/env bash
# The foliage passes' overdraw and cost (issue 19, docs/PERFORMANCE.md): `terramp profile` over the
# synthetic default dataset (its default path) and over nc (config/paths/nc.toml), trees drawn,
# at 1280 × 720 balanced: once with `gpu.count_fragments` (fragments shaded per pixel covered, per
# pass, and samples written; frames serialised by the readback) and once without (the passes'
# times, to quote); each without and with the seeds' depth prepass (`draw_seeds.depth_prepass`).
#
#   FRAMES=20 scripts/overdraw.sh            # prints both tables per dataset
#
# Environment: FRAMES (20), WARMUP (10), WIDTH × HEIGHT (1280 × 720), OUT (out/overdraw: the JSON
# of each run), DATA_DIR (data/trade: synthetic/, nc/ and the impostors with nc's forest sample,
# as scripts/trade_data.sh and `terramp-data bake --classes nc` make them). Needs the release build.
set -euo pipefail
cd "$(dirname "$0")/.."
FRAMES=${FRAMES:-20}
WARMUP=${WARMUP:-10}
WIDTH=${WIDTH:-1280}
HEIGHT=${HEIGHT:-720}
OUT=${OUT:-out/overdraw}
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
bin=${CARGO_TARGET_DIR:-target}/release/terramp
[ -x "$bin" ] || { echo "no $bin: cargo build --release" >&2; exit 1; }
DATA_DIR=${DATA_DIR:-data/trade}
mkdir -p "$OUT"
for d in synthetic nc impostors; do
  [ -d "$DATA_DIR/$d" ] || { echo "no $DATA_DIR/$d: scripts/trade.sh builds it" >&2; exit 1; }
done

trees() { # impostors, count_fragments, depth_prepass → a settings file
  local file="$OUT/settings-$(basename "$1")-$2-$3.toml"
  printf '[gpu]\ncount_fragments = %s\n[draw_seeds]\nimpostors = "%s"\ndepth_prepass = %s\n' \
    "$2" "$(realpath "$1")" "$3" >"$file"
  echo "$file"
}

run() { # name, dataset, impostors, path args...
  local name=$1 dataset=$2 impostors=$3
  shift 3
  for prepass in false true; do
    for count in true false; do
      echo "## $name, draw_seeds.depth_prepass = $prepass, gpu.count_fragments = $count"
      "$bin" profile --dataset "$dataset" "$@" --frames "$FRAMES" --warmup "$WARMUP" --width "$WIDTH" \
        --height "$HEIGHT" --settings "$(trees "$impostors" "$count" "$prepass")" \
        --json "$OUT/$name-$prepass-$count.json" 2>/dev/null |
        grep -E "draw_seeds|texcells|Overdraw|Frame \(wall|Seeds (checked|selected)"
    done
  done
}

run synthetic "$DATA_DIR/synthetic" "$DATA_DIR/impostors"
run nc "$DATA_DIR/nc" "$DATA_DIR/impostors" --path config/paths/nc.toml
