#!/usr/bin/env bash
# The speed trade (issues 6 and 12): `terramp sweep` over nc/, zion/ and the synthetic default
# dataset, every preset judged against the ground truth (`terramp truth`: every seed as its mesh,
# finest tiles, 4 × 4 supersampled), and docs/TRADE.md written from what it measured. One command:
#
#   scripts/trade.sh            # needs ../shared/data (nc/, zion/ and models/)
#
# 1. Builds the release binaries, then the datasets into DATA_DIR (default data/trade; each is
#    reused while `terramp info` reads it): nc/ (DEM, Landsat bands 3,2,1, land use) and zion/ (DEM,
#    NLCD) as data-tools/tests/support builds them, and the synthetic default (`synth --size 1024`).
# 2. Bakes the 11 shared models into impostors (reused when present) and writes a settings layer
#    that points `draw_seeds.impostors` at them, so that every frame shows its trees and the ground
#    truths draw their meshes.
# 3. Sweeps each dataset along its default path (nc/ and zion/: the generated orbit; synthetic:
#    config/paths/default.toml) into docs/trade/<name>/ (trade.csv, trade.json, trade.png,
#    trade.md), then writes docs/TRADE.md (`scripts/trade_page.py`): how it was measured, each
#    dataset's tables and plot, and the issue's acceptance checks computed from the JSON.
#
# Besides the presets, every dataset's sweep varies each speed knob over three values, one at a
# time from the `balanced` preset (`--series --series-from balanced`), so that trade.png shows a
# front of some thirty points.
#
# Environment: FRAMES (60 timed frames per point), WARMUP (10 per round), ROUNDS (3: the timed
# frames split into rounds that each time every point in turn), SAMPLES (3 poses), PRESETS
# (fast,balanced,accurate), SERIES_FROM (balanced), FRONT (1; 0 measures the presets alone),
# POPPING_FRAMES (12), WIDTH × HEIGHT (1280 × 720), TRUTH_SUPERSAMPLE (4), TRUTH_REACH_M (4000),
# DATA_DIR, SWEEP ("synthetic nc zion": the datasets to sweep again; the page is always written
# from all three folders' trade.json, so SWEEP=nc re-measures nc/ alone and SWEEP= only rewrites
# the page).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models

frames="${FRAMES:-60}"
warmup="${WARMUP:-10}"
samples="${SAMPLES:-3}"
presets="${PRESETS:-fast,balanced,accurate}"
width="${WIDTH:-1280}"
height="${HEIGHT:-720}"
# Relative to the repository root, so the figures' paths name no one's machine.
data="${DATA_DIR:-data/trade}"
mkdir -p "$data" docs/trade

cargo build --release --workspace -q
started=$(date +%s)
# The datasets, the impostors and the settings layer $trees that draws with them.
source scripts/trade_data.sh

# The front's knobs: three values each besides balanced's own (in brackets).
knobs=(
    "tlm.cells=32,48,96"                                                   # [64]
    "tlm.radial_bands_m=[500,1000,3000],[1000,2000,3000],[1400,2200,3000]" # [700,1400,3000]
    "seeds.occlusion_tolerance_m=1,2,20"                                   # [5]
    "seeds.density_scale=0.25,0.5,0.75"                                    # [1]
    "seeds.seeds_per_pattern=1024,3072,4096"                               # [2048]
    "draw_seeds.reach_m=[500,700,1400,3000],[600,1000,1400,3000],[1200,1300,1400,3000]" # mesh reach [800]
    "draw_seeds.fade_fraction=0,0.05,0.25"                                 # [0.1]
    "terrain.triangle_px=2,4,16"                                           # [8]
    "cache.imagery_slots=32,48,192"                                        # [96]
    "draw_seeds.samples=4"                                                 # [1]
    "seeds.reference_height_m=1,5,10"                                      # [2]
    # How far seeds reach at all: the last band and the last draw reach together [3000].
    "tlm.radial_bands_m+draw_seeds.reach_m=[500,1000,2000]+[800,1000,1400,2000],[700,1400,4000]+[800,1000,1400,4000]"
)
front=()
if [[ "${FRONT:-1}" != 0 ]]; then
    front=(--series --series-from "${SERIES_FROM:-balanced}")
    for k in "${knobs[@]}"; do front+=(--knob "$k"); done
fi

for name in ${SWEEP-synthetic nc zion}; do
    echo "## sweep $name" >&2
    "$terramp" sweep --dataset "$data/$name" --out "docs/trade/$name" --presets "$presets" \
        --frames "$frames" --warmup "$warmup" --timing-rounds "${ROUNDS:-3}" --samples "$samples" --width "$width" --height "$height" \
        --truth-supersample "${TRUTH_SUPERSAMPLE:-4}" --truth-reach-m "${TRUTH_REACH_M:-4000}" \
        --popping-frames "${POPPING_FRAMES:-12}" --settings "$trees" "${front[@]}"
done

python3 scripts/trade_page.py "$frames" "$warmup" "$((($(date +%s) - started) / 60))" >docs/TRADE.md
echo "wrote docs/TRADE.md and docs/trade/{synthetic,nc,zion}/" >&2
