#!/usr/bin/env bash
# Texcells judged against a ground truth that grows every tree to the horizon (issue 13): a
# `terramp sweep` over nc/ along config/paths/nc_far_forest.toml (from the issue's view at 350 m up
# to 2 km up over the whole forest), its truths grown to TRUTH_REACH_M (12 km: every tree of the map
# in view as its mesh), judged per distance band. One command:
#
#   scripts/texcells_truth.sh        # needs ../shared/data (nc/ and models/)
#
# Points: `balanced` (texcells to 12 km, taking on as much of the imagery's colour as the seeds
# do), the same without texcells (`texcells.reach_m` 0: the bare ground beyond the last billboard
# clouds, as before texcells), with silhouette texcells where rays descend less than 3° or 6°
# (`texcells.silhouette_deg`; balanced draws regular slices however grazing the view), and with
# texcells taking on none of the imagery's colour (`texcells.ground_blend` 0) or most of it (0.7).
# In the sweep's band table (docs/texcells/trade.md) the "texcells" band, from the last clouds'
# reach to the truth's, gives the figures of issue 13: the frame's FLIP there, and its forest cover
# (recall: the share of the truth's forest pixels the frame draws on; precision: the share of the
# pixels it draws on that are the truth's forest).
#
# Environment: SAMPLES (2 poses; each truth takes ~5 minutes on 2 cores), WIDTH × HEIGHT
# (960 × 540), TRUTH_SUPERSAMPLE (4), TRUTH_REACH_M (12000), DATA_DIR (data/trade), OUT
# (docs/texcells).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models
data="${DATA_DIR:-data/trade}"
out="${OUT:-docs/texcells}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

# The impostors with the nc table's forest sample beside them, apart from the trade's folder (whose
# sweeps run without texcells: their truths stop at 4 km).
forest="$data/forest"
if [[ ! -d "$forest/texcells/5" ]]; then
    rm -rf "$forest"
    cp -r "$impostors" "$forest"
    "$terramp_data" bake --classes nc --models "$shared/models" --out "$forest"
fi
layer="$data/forest.toml"
printf '# Written by scripts/texcells_truth.sh: seeds and texcells.\n[draw_seeds]\nimpostors = "%s"\n' \
    "$(cd "$forest" && pwd)" >"$layer"

"$terramp" sweep --dataset "$data/nc" --path config/paths/nc_far_forest.toml --out "$out" \
    --presets balanced --series --knob texcells.reach_m=0 --knob texcells.silhouette_deg=3,6 \
    --knob texcells.ground_blend=0,0.7 \
    --frames "${FRAMES:-6}" --warmup 4 --timing-rounds 1 --samples "${SAMPLES:-2}" \
    --width "${WIDTH:-960}" --height "${HEIGHT:-540}" --truth-supersample "${TRUTH_SUPERSAMPLE:-4}" \
    --truth-reach-m "${TRUTH_REACH_M:-12000}" --popping-frames 0 --settings "$layer"
