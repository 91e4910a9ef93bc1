#!/usr/bin/env bash
# What drawing on the Earth costs (issue 44): nc's flight (config/paths/nc.toml, the trade's
# trees) drawn on the Earth and as the flat sheet (`render.curved_earth`), one commit, one
# dataset. First one counting run of each (`gpu.count_fragments`: the foliage passes' triangles
# and fragments, which must agree within 1 %), then frame times in alternating rounds. One
# command (needs ../shared/data: nc/, models/):
#
#   scripts/earth_cost.sh
#   scripts/earth_cost.sh globe    # only what GLOBE's tile costs from 10 km up (needs globe/)
#
# `globe`: GLOBE's tile (built into DATA_DIR/globe as scripts/docs_images.sh builds it), one frame
# settled from 10 km above five places at four pitches, with and without horizon culling
# (`terrain.horizon_culling`): the terrain's nodes and the Tile Load Map's visible cells, counts
# that do not depend on the adapter.
#
# nc is the trade's (scripts/trade_data.sh) when its manifest records where it lies ([earth]);
# one built before that is not rebuilt in place: nc_earth is built beside it the same way.
#
# Environment: FRAMES (60), WARMUP (10), ROUNDS (3), DATA_DIR (data/trade), OUT
# (/tmp/terramp-earth-cost), CARGO_TARGET_DIR.
set -euo pipefail

if [[ ${1:-} == globe ]]; then
    source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" globe
else
    source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc models
fi
data="${DATA_DIR:-data/trade}"
out="${OUT:-/tmp/terramp-earth-cost}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

if [[ ${1:-} == globe ]]; then
    globe="$data/globe"
    if ! grep -q '^\[earth\]' "$globe/manifest.toml" 2>/dev/null; then
        "$terramp_data" build --dem "$shared/globe/globe_g_30arcsec.tif" --out "$globe" >/dev/null
    fi
    echo "| place | pitch | nodes | nodes, no horizon culling | TLM cells | TLM cells, no horizon culling |"
    echo "|---|---|---|---|---|---|"
    for place in 45,25 10,45 80,5 86.9,27.9 60,40; do
        for pitch in 0 -10 -30 -90; do
            row="| $place | $pitch |"
            nodes=() cells=()
            for culling in true false; do
                printf '[terrain]\nhorizon_culling = %s\n' "$culling" >"$out/globe-$culling.toml"
                line=$("$terramp" render --dataset "$globe" --camera "lonlat:$place,10000,30,$pitch" \
                    --width 1920 --height 1080 --settings "$out/globe-$culling.toml" --out "$out/globe.png" 2>/dev/null \
                    | grep ' nodes, ')
                nodes+=("$(sed -E 's/.*: ([0-9]+) nodes.*/\1/' <<<"$line")")
                cells+=("$(sed -E 's/.* ([0-9]+) TLM cells.*/\1/' <<<"$line")")
            done
            echo "$row ${nodes[0]} | ${nodes[1]} | ${cells[0]} | ${cells[1]} |"
        done
    done
    exit 0
fi

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
