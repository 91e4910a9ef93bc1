#!/usr/bin/env bash
# What drawing on the Earth costs (issue 44): nc's flight (config/paths/nc.toml, the trade's
# trees) drawn on the Earth and as the flat sheet (`render.curved_earth`), one commit, one
# dataset. First one counting run of each (`gpu.count_fragments`: the foliage passes' triangles
# and fragments, which must agree within 1 %), then frame times in alternating rounds. One
# command (needs ../shared/data: nc/, models/):
#
#   scripts/earth_cost.sh
#
# nc is the trade's (scripts/trade_data.sh) when its manifest records where it lies ([earth]);
# one built before that is not rebuilt in place: nc_earth is built beside it the same way.
#
# Environment: FRAMES (60), WARMUP (10), ROUNDS (3), DATA_DIR (data/trade), OUT
# (/tmp/terramp-earth-cost), CARGO_TARGET_DIR.
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc models
data="${DATA_DIR:-data/trade}"
out="${OUT:-/tmp/terramp-earth-cost}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

nc="$data/nc"
if ! grep -q '^\[earth\]' "$nc/manifest.toml"; then
    nc="$data/nc_earth"
    build nc_earth "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" \
        --imagery "$shared/nc/landsat_multiband.tif" --bands 3,2,1 \
        --landcover "$shared/nc/landuse_r.tif" --classes nc
fi

# layer NAME CURVED COUNT: the trade's trees, on the Earth or flat, counting fragments or not.
layer() {
    { cat "$trees"; printf '[render]\ncurved_earth = %s\n[gpu]\ncount_fragments = %s\n' "$2" "$3"; } >"$out/$1.toml"
    echo "$out/$1.toml"
}

profile() {
    "$terramp" profile --dataset "$nc" --path config/paths/nc.toml --frames "${FRAMES:-60}" \
        --warmup "${WARMUP:-10}" --settings "$1" 2>/dev/null
}

echo "## counts: the foliage passes' fragments and triangles" >&2
for curved in true false; do
    profile "$(layer "count-$curved" "$curved" true)" | grep -E "fragments / covered pixel" \
        | sed "s|^|curved_earth = $curved: |"
done

echo "## frame times, alternating rounds" >&2
for round in $(seq "${ROUNDS:-3}"); do
    for curved in true false; do
        profile "$(layer "time-$curved" "$curved" false)" \
            | grep -E "Total GPU passes|Frame \(wall|terrain_select|^ *terrain " \
            | sed "s|^|curved_earth = $curved, round $round: |"
    done
done
