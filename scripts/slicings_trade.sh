#!/usr/bin/env bash
# Slicings (Jakulin 2000) against the billboard clouds they replace (issue 15): `terramp sweep`
# over nc/ along its default path, from `balanced` (LOD 1, 800–1000 m, the 17-plane cloud) and the
# same with `draw_seeds.slicings` (LOD 1 the trunk as a mesh and the crown's two nearest slicings,
# blended), then both with meshes only to 300 m (LOD 1 from 300 m, where slicings show more), each
# judged against the ground truth (every seed its whole mesh, 4² samples) per distance band: time
# per pass, FLIP per band, popping along the sweep's flight. The models are baked once with their
# slicings (6 × 5) into their own folder, which every point (and the truth) draws from. Writes
# docs/trade/slicings/. One command:
#
#   scripts/slicings_trade.sh        # needs ../shared/data (nc/ and models/)
#
# Environment: FRAMES (12), WARMUP (4), SAMPLES (2), WIDTH × HEIGHT (960 × 540), TEXELS (512),
# DATA_DIR (data/trade), OUT (docs/trade/slicings).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models
data="${DATA_DIR:-data/trade}"
out="${OUT:-docs/trade/slicings}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

sliced="$data/sliced"
args=()
for m in "${models[@]}"; do args+=(--model "$shared/models/$m.glb"); done
if [[ ! -f "$sliced/Tree_1/slicing_mip0.png" ]]; then
    "$terramp_data" bake "${args[@]}" --out "$sliced" --texels "${TEXELS:-512}" --slicings 6x5 >/dev/null
fi
layer="$data/sliced.toml"
printf '# Written by scripts/slicings_trade.sh: seeds with slicings baked.\n[draw_seeds]\nimpostors = "%s"\n' \
    "$(cd "$sliced" && pwd)" >"$layer"

"$terramp" sweep --dataset "$data/nc" --out "$out" --presets balanced \
    --frames "${FRAMES:-12}" --warmup "${WARMUP:-4}" --timing-rounds 2 --samples "${SAMPLES:-2}" \
    --width "${WIDTH:-960}" --height "${HEIGHT:-540}" --truth-supersample 4 --truth-reach-m 4000 \
    --popping-frames 12 --settings "$layer" \
    --knob draw_seeds.slicings=false,true \
    --knob "draw_seeds.reach_m=[800,1000,1400,3000],[300,1000,1400,3000]"
