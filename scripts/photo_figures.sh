#!/usr/bin/env bash
# The photograph's figures of docs/photo.md that need more than one `terramp photo` (issue 43):
# the forest's edges with and without the dithered class edges, the seeds drawn before and after,
# the mesh band against the earlier build's ground truth in luminance only, and the straight
# descent from 10 km to 300 m. One command:
#
#   scripts/photo_figures.sh            # needs ../shared/data (nc/ and models/), data/trade as
#                                       # scripts/trade.sh builds it (nc/ and forest/)
#
# "Before" is the release build of c1e844b (the last commit before the colour follow-up), built
# once in a worktree of its own, or BEFORE_BIN if given. Everything is 640 × 640, balanced, nc's
# species as the trade's impostors with nc's forest sample beside them (data/trade/forest), over
# nc's centre. Writes into OUT (default target/photo_figures) and prints each table.
#
# 1. Edges: `terramp photo` from 3 km straight down, 1.5 km at 45°, 1 km straight down and 300 m
#    at 30°, with `seeds.class_edge_dither` on (the default) and off: the trees' step share
#    (`terramp::photo::edges`: 0 filtered, 1 on the land cover's cells).
# 2. Seeds drawn: `terramp fly` holding each view 12 frames, before and after; the last frame's
#    seeds selected (pass 3's records: what pass 4 draws).
# 3. The mesh band: the truths of the 300 m view (`terramp truth`, 4 × 4 samples, seeds to 4 km)
#    by both builds, the earlier build's frame against its truth, this build's frame against the
#    earlier truth and against its own (`terramp photo --truth`): FLIP over the pixels whose ground
#    lies within `draw_seeds.reach_m[0]`, in colour, in luminance only and in detail only
#    (`terramp::photo::truth`).
# 4. The descent: `terramp photo --descend-to 300` from 10.1 km above the datum straight down,
#    2 % of the height a frame (about 175 frames, ~7 minutes here), with a small seed's mean (the
#    default) and without it (`draw_seeds.prefilter_small = false`), by ranges of height.
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc models

data="${DATA_DIR:-data/trade}"
out="${OUT:-target/photo_figures}"
mkdir -p "$out"
for need in "$data/nc/manifest.toml" "$data/forest"; do
    [[ -e $need ]] || { echo "photo_figures.sh: $need is missing: run scripts/trade.sh first" >&2; exit 1; }
done
cargo build --release -q --bin terramp
terramp="$root/target/release/terramp"
before_bin="${BEFORE_BIN:-}"
if [[ -z $before_bin ]]; then
    tree="$out/before-c1e844b"
    [[ -d $tree ]] || git worktree add --detach "$tree" c1e844b >/dev/null
    (cd "$tree" && CARGO_TARGET_DIR="$root/$out/before-target" cargo build --release -q --bin terramp)
    before_bin="$root/$out/before-target/release/terramp"
fi
forest="$(cd "$data/forest" && pwd)"
printf '[draw_seeds]\nimpostors = "%s"\n' "$forest" >"$out/trees.toml"
printf '[draw_seeds]\nimpostors = "%s"\n[seeds]\nclass_edge_dither = false\n' "$forest" >"$out/on_cells.toml"
view=(--dataset "$data/nc" --width 640 --height 640)
views=(3km:637500,221750,3000,0,-89 1500m_45:637500,221750,1600,0,-45 1km:637500,221750,1100,0,-89
    300m_30:637500,221750,400,0,-30)
field() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

echo "== trees' edges, step share between seeded classes (trees near an edge): dithered | on the cells"
for v in "${views[@]}"; do
    name=${v%%:*} pose=${v#*:}
    for s in trees on_cells; do
        "$terramp" photo "${view[@]}" --camera "$pose" --settings "$out/$s.toml" --out "$out/edges_${s}_$name" \
            >/dev/null 2>&1
    done
    e="d['figures']['edges']['between_seeded']"
    printf '%-10s %7.3f (%5d) | %7.3f (%5d)\n' "$name" \
        "$(field "$out/edges_trees_$name/photo.json" "$e['step_share']")" \
        "$(field "$out/edges_trees_$name/photo.json" "$e['trees']")" \
        "$(field "$out/edges_on_cells_$name/photo.json" "$e['step_share']")" \
        "$(field "$out/edges_on_cells_$name/photo.json" "$e['trees']")"
done

echo "== seeds selected (drawn) per frame, held 12 frames: before | after"
for v in "${views[@]}"; do
    name=${v%%:*} pose=${v#*:}
    IFS=, read -r x y z yaw pitch <<<"$pose"
    path="$out/hold_$name.toml"
    for _ in 1 2; do
        printf '[[key]]\nat = [%s, %s, %s]\nyaw_deg = %s\npitch_deg = %s\n\n' "$x" "$y" "$z" "$yaw" "$pitch"
    done >"$path"
    counts=()
    for bin in "$before_bin" "$terramp"; do
        rm -rf "$out/fly_$name"
        "$bin" fly "${view[@]}" --settings "$out/trees.toml" --path "$path" --frames 12 --save-every 0 \
            --out "$out/fly_$name" >/dev/null 2>&1
        counts+=("$(tail -n 1 "$out/fly_$name/log.jsonl" | python3 -c \
            "import json,sys; print(json.load(sys.stdin)['report']['seeds']['selected'])")")
    done
    printf '%-10s %8s | %8s\n' "$name" "${counts[0]}" "${counts[1]}"
done

echo "== the mesh band of the 300 m view: FLIP colour / luminance / detail (frame against truth)"
pose=637500,221750,400,0,-30
for who in before after; do
    bin=$terramp
    [[ $who == before ]] && bin=$before_bin
    "$bin" truth "${view[@]}" --camera "$pose" --settings "$out/trees.toml" --out "$out/truth_${who}_300m" \
        >/dev/null 2>&1
done
"$before_bin" render "${view[@]}" --camera "$pose" --settings "$out/trees.toml" --out "$out/before_300m.png" \
    >/dev/null 2>&1
for pair in before:before after:before after:after; do
    frame=${pair%%:*} truth=${pair#*:}
    given=()
    [[ $frame == before ]] && given=(--amplified "$out/before_300m.png")
    "$terramp" photo "${view[@]}" --camera "$pose" --settings "$out/trees.toml" "${given[@]}" \
        --truth "$out/truth_${truth}_300m/truth.png" --out "$out/truth_$frame-$truth" >/dev/null 2>&1
    printf '%-6s frame, %-6s truth: %s\n' "$frame" "$truth" "$(field "$out/truth_$frame-$truth/photo.json" \
        "'%.4f / %.4f / %.4f over %d px' % tuple(d['truth'][k] for k in ('colour', 'luminance', 'detail', 'pixels'))")"
done

printf '[draw_seeds]\nimpostors = "%s"\nprefilter_small = false\n' "$forest" >"$out/no_prefilter.toml"
ranges() {
    python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("heights         pairs  amplified  photograph  own (at)                   own > 3")
for name, lo, hi in [("10 km to 5 km", 5000, 1e9), ("5 km to 3.2 km", 3200, 5000),
                     ("3.2 km to 1 km", 1000, 3200), ("1 km to 300 m", 0, 1000)]:
    sel = [r for r in rows if lo <= float(r["next_height_m"]) < hi]
    worst = max(sel, key=lambda r: float(r["own"]))
    top = lambda k: max(float(r[k]) for r in sel)
    at = "%.2f (%.0f to %.0f m)" % (float(worst["own"]), float(worst["height_m"]), float(worst["next_height_m"]))
    print("%-15s %5d %10.2f %11.2f  %-26s %7d" % (name, len(sel), top("amplified"), top("photograph"), at,
                                                  sum(float(r["own"]) > 3 for r in sel)))
PY
}
for s in trees no_prefilter; do
    echo "== the descent from 10.1 km to 300 m at 2 % a frame ($s.toml), the largest change of a block, CIEDE2000"
    "$terramp" photo "${view[@]}" --camera 637500,221750,10100,0,-89 --settings "$out/$s.toml" \
        --descend-to 300 --out "$out/descent_$s" >/dev/null 2>&1
    ranges "$out/descent_$s/descent.csv"
done
