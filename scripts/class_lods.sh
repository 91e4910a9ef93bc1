#!/usr/bin/env bash
# What a class's own last draw LOD buys and costs (issue 13, "model only what a scene requires"):
# `terramp sweep` over nc/ along its default path from `balanced`, once with nc's table (every
# class's seeds to the last billboard-cloud band) and once with its sparse classes (developed,
# agriculture, herbaceous, shrubland, sediment: bushes, stones and scattered trees) drawn to their
# first LODS draw LODs only (`[[class]] seed_lods`), each judged against the ground truth (every
# seed its whole mesh; the sweep renders the second table's truths apart, and they are the same
# images: the rule changes what is drawn, not what grows). Writes
# docs/trade/class_lods/ (trade.md: time per pass, recall, FLIP per distance band). One command:
#
#   scripts/class_lods.sh        # needs ../shared/data (nc/ and models/)
#
# Environment: LODS (2: the mesh and the first billboard-cloud band), FRAMES (24), WARMUP (6),
# SAMPLES (3), WIDTH × HEIGHT (1280 × 720), DATA_DIR (data/trade), OUT (docs/trade/class_lods).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models
data="${DATA_DIR:-data/trade}"
out="${OUT:-docs/trade/class_lods}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

# nc's table with every class that has no texcells (the sparse ones) stopping at LODS.
sparse="$data/nc_sparse_lods.toml"
awk -v lods="${LODS:-2}" '
    /^\[\[class\]\]/ { in_class = 1 }
    in_class && /^name = / && $0 !~ /"(forest|water)"/ { print; print "seed_lods = " lods; next }
    { print }
' config/classes/nc.toml >"$sparse"
[[ $(grep -c '^seed_lods' "$sparse") == 5 ]] || { echo "class_lods.sh: expected 5 sparse classes in nc.toml" >&2; exit 1; }

"$terramp" sweep --dataset "$data/nc" --out "$out" --presets balanced \
    --frames "${FRAMES:-24}" --warmup "${WARMUP:-6}" --timing-rounds 3 --samples "${SAMPLES:-3}" \
    --width "${WIDTH:-1280}" --height "${HEIGHT:-720}" --truth-supersample 4 --truth-reach-m 4000 \
    --popping-frames 12 --settings "$trees" --series --series-from balanced \
    --knob "seeds.class_table=$sparse"
