#!/usr/bin/env bash
# What the round Earth changes in docs/TRADE.md's accuracy (issue 44): nc and zion built with
# their [earth], each preset swept as scripts/trade.sh sweeps it (the trade's trees, the ground
# truth, the summit oracle, the photograph), once drawn on the Earth and once as the flat sheet
# (`render.curved_earth = false`), one commit, one dataset. The accuracy figures are deterministic;
# the times here are a few frames' and mean nothing (scripts/earth_cost.sh measures the cost).
# One command (needs ../shared/data: nc/, zion/, models/):
#
#   scripts/earth_trade.sh
#
# nc and zion are the trade's (scripts/trade_data.sh) where their manifests record where they lie;
# ones built before that are not rebuilt in place: nc_earth and zion_earth are built beside them.
# Prints each dataset's preset rows, on the Earth then flat; the sweeps are kept in OUT.
#
# Environment: FRAMES (6), WARMUP (2), SAMPLES (3), DATA_DIR (data/trade), OUT
# (/tmp/terramp-earth-trade), CARGO_TARGET_DIR.
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models
data="${DATA_DIR:-data/trade}"
out="${OUT:-/tmp/terramp-earth-trade}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

declare -A dataset=([nc]="$data/nc" [zion]="$data/zion")
if ! grep -q '^\[earth\]' "$data/nc/manifest.toml"; then
    dataset[nc]="$data/nc_earth"
    build nc_earth "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" \
        --imagery "$shared/nc/landsat_multiband.tif" --bands 3,2,1 \
        --landcover "$shared/nc/landuse_r.tif" --classes nc
fi
if ! grep -q '^\[earth\]' "$data/zion/manifest.toml"; then
    dataset[zion]="$data/zion_earth"
    build zion_earth "$terramp_data" build --dem "$shared/zion/dem_utm12n_30m.tif" \
        --landcover "$shared/zion/nlcd_utm12n_30m.tif" --classes nlcd
fi

for name in nc zion; do
    for curved in true false; do
        layer="$out/$name-$curved.toml"
        { cat "$trees"; printf '[render]\ncurved_earth = %s\n' "$curved"; } >"$layer"
        echo "## $name, curved_earth = $curved" >&2
        "$terramp" sweep --dataset "${dataset[$name]}" --out "$out/$name-$curved" \
            --presets fast,balanced,accurate --frames "${FRAMES:-6}" --warmup "${WARMUP:-2}" --timing-rounds 1 \
            --samples "${SAMPLES:-3}" --width 1280 --height 720 --truth-supersample 4 --truth-reach-m 4000 \
            --popping-frames 12 --settings "$layer" >/dev/null
    done
    echo "### $name (${dataset[$name]}): on the Earth, then flat"
    head -2 "$out/$name-true/trade.md"
    for curved in true false; do
        grep -E '^\| (fast|balanced|accurate) \|' "$out/$name-$curved/trade.md" | sed "s/^| /| $curved: /"
    done
done
