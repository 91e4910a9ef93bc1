#!/usr/bin/env bash
# Generated trees measured (issue 14): what the continuous LOD buys and costs against the ground
# truth, the demo's frame with generated trees against the shared models, and the bake time of
# each generated tree. One command (needs ../shared/data: nc/, zion/, models/):
#
#   scripts/continuous_lod.sh
#
# 1. Grows the embedded default's generated trees (config/classes/nc_generated.toml) with
#    `terramp-data tree` into $DATA_DIR/generated-models and bakes each (timed, one at a time;
#    reused while current) into $DATA_DIR/impostors beside the shared models' (scripts/trade_data.sh).
# 2. Sweeps the synthetic default with those trees (`seeds.class_table = "nc-generated"`) from
#    `balanced`: draw_seeds.continuous_lod off (mesh → 17-plane cloud) and on (mesh → continuous
#    range → 8-plane cloud), each with the first cloud reaching 1000 m (balanced) and 1400 m,
#    judged against the truth (every tree its whole mesh) into docs/trade/continuous_lod/.
# 3. Profiles the demo's flight (config/paths/default.toml) with the generated trees and with the
#    shared models, in alternating rounds, and prints both medians.
#
# Environment: FRAMES (24), WARMUP (6), PROFILE_FRAMES (60; 0 skips step 3), ROUNDS (2), DATA_DIR
# (data/trade), CARGO_TARGET_DIR.
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models
data="${DATA_DIR:-data/trade}"
mkdir -p "$data" docs/trade
cargo build --release --workspace -q
source scripts/trade_data.sh

models="$data/generated-models"
mkdir -p "$models"
echo "## generated trees: grown and baked one at a time (seconds)" >&2
for name in $(grep -o 'tree-[a-z]*-s[0-9]*-h[0-9]*' config/classes/nc_generated.toml | sort -u); do
    IFS=- read -r _ species seed health <<<"$name"
    glb="$models/$name.glb"
    [[ -f "$glb" ]] || "$terramp_data" tree --species "$species" --seed "${seed#s}" \
        --health "$(awk "BEGIN { print ${health#h} / 100 }")" --out "$glb" >/dev/null
    started=$(date +%s.%N)
    "$terramp_data" bake --model "$glb" --out "$impostors" --texels 256 --missing >/dev/null
    awk -v name="$name" -v t0="$started" -v t1="$(date +%s.%N)" 'BEGIN { printf "%s\t%.1f s\n", name, t1 - t0 }' >&2
done
generated="$data/generated.toml"
printf '# Written by scripts/continuous_lod.sh: the generated trees, drawn.\n[seeds]\nclass_table = "nc-generated"\n[draw_seeds]\nimpostors = "%s"\n' \
    "$(cd "$impostors" && pwd)" >"$generated"

echo "## sweep: continuous LOD off and on" >&2
"$terramp" sweep --dataset "$data/synthetic" --out docs/trade/continuous_lod --presets balanced \
    --frames "${FRAMES:-24}" --warmup "${WARMUP:-6}" --timing-rounds 3 --samples 3 --width 1280 --height 720 \
    --truth-supersample 4 --truth-reach-m 4000 --popping-frames 12 --settings "$generated" \
    --series --series-from balanced \
    --knob "draw_seeds.continuous_lod=true" \
    --knob "draw_seeds.reach_m=[800,1400,2000,3000]" \
    --knob "draw_seeds.continuous_lod+draw_seeds.reach_m=true+[800,1400,2000,3000]"

[[ "${PROFILE_FRAMES:-60}" != 0 ]] || exit 0
echo "## profile: the demo's flight, generated trees against the shared models" >&2
for round in $(seq "${ROUNDS:-2}"); do
    for layer in "$generated" "$trees"; do
        "$terramp" profile --dataset "$data/synthetic" --frames "${PROFILE_FRAMES:-60}" --warmup 10 \
            --settings "$layer" --json "$data/profile-$(basename "$layer" .toml)-$round.json" \
            2>/dev/null | grep -E "draw_seeds|Total GPU passes|Frame \(wall|Seeds selected" | sed "s|^|$(basename "$layer" .toml) round $round: |"
    done
done
