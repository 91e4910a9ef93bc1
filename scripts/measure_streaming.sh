#!/usr/bin/env bash
# Measures streaming against dataset size (issue 3) with a release `terramp`, and prints figures:
#
# 1. Synthesizes two datasets of identical ground where they overlap, one 16× the area of the
#    other (`synth --size 1024`: 10 km square; `--size 4096`: 41 km square; about 2 GB and two
#    minutes), or reuses them from OUT_DIR when `terramp info` still reads them.
# 2. Flies the same camera paths over both, REPEATS times each, small and large interleaved so
#    that load from other work on the machine falls on both: `config/paths/default.toml` (the
#    camera stays within the first 10 km, but the view reaches past it, so the large dataset shows
#    more ground) and `interior.toml` (written to OUT_DIR: pitched down so the whole view stays
#    within the small dataset: the same view over both). `scripts/streaming_summary.py` prints
#    each flight's figures and the ratio large / small with a flat-within-10 % verdict.
#    Then a still camera (`still.toml`: 60 frames, the same view over both): rendering alone.
# 3. Camera jump on the large dataset: JUMP_HOLD frames at one corner, then JUMP_HOLD frames at the
#    opposite one (a path of one key per frame, so the jump is instant): frames from the jump to a
#    resolved view, and bytes read against bytes of the tiles the new view needs.
# 4. Writes a frame strip of the default path over the small dataset at 640 × 360 to
#    docs/flight_0..5.png, and the frames just after the jump and once resolved to
#    docs/flight_jump_before.png / docs/flight_jump_after.png (the jump again, at 640 × 360).
#
# Always exits 0 once the flights ran: the verdicts are measurements, not tests.
#
# Usage: scripts/measure_streaming.sh [OUT_DIR]   (default: a fresh temporary folder, removed after)
# Environment: FRAMES (240), WIDTH × HEIGHT (1280 × 720), REPEATS (3), JUMP_HOLD (60), IMAGES_ONLY
# (1: only the datasets and step 4, as scripts/docs_images.sh makes the images).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
unset RUST_BACKTRACE

frames="${FRAMES:-240}"
width="${WIDTH:-1280}"
height="${HEIGHT:-720}"
repeats="${REPEATS:-3}"
hold="${JUMP_HOLD:-60}"

if [[ $# -ge 1 ]]; then
    out="$1"
    mkdir -p "$out"
    out="$(cd "$out" && pwd)"
else
    out="$(mktemp -d "${TMPDIR:-/tmp}/terramp-streaming.XXXXXX")"
    trap 'rm -rf "$out"' EXIT
fi

cargo build --release --quiet --workspace --manifest-path "$root/Cargo.toml"
bin="$root/target/release/terramp"
synth_bin="$root/target/release/terramp-data"
summary="$root/scripts/streaming_summary.py"

dataset() {
    local size="$1" dir="$out/synth$1"
    if "$bin" info --dataset "$dir" >/dev/null 2>&1; then
        echo "dataset synth$size: reusing $dir" >&2
    else
        echo "dataset synth$size: synthesizing into $dir" >&2
        local start=$SECONDS
        "$synth_bin" synth --size "$size" --out "$dir" >"$out/synth$size.log" 2>&1
        echo "dataset synth$size: $((SECONDS - start)) s" >&2
    fi
    "$bin" info --dataset "$dir" | sed 's/^/  /'
}

# One key per line of "x y z yaw pitch" on stdin, written as a path file.
write_path() {
    while read -r x y z yaw pitch; do
        printf '[[key]]\nat = [%s, %s, %s]\nyaw_deg = %s\npitch_deg = %s\n\n' "$x" "$y" "$z" "$yaw" "$pitch"
    done >"$1"
}

# fly NAME DATASET PATH FRAMES SAVE_EVERY WIDTH HEIGHT: the log lands in $out/NAME/log.jsonl.
fly() {
    local name="$1" dataset="$2" path="$3" n="$4" save="$5" w="$6" h="$7"
    rm -rf "${out:?}/$name"
    "$bin" fly --dataset "$dataset" --path "$path" --frames "$n" --save-every "$save" \
        --width "$w" --height "$h" --out "$out/$name" >"$out/$name.out" 2>"$out/$name.err" ||
        { echo "fly $name failed:" >&2; cat "$out/$name.err" >&2; exit 1; }
    echo "  $name: $(cat "$out/$name.out") [load average after: $(cut -d' ' -f1-3 /proc/loadavg)]" >&2
}

changed="$(git -C "$root" status --porcelain -- src shaders data-tools config Cargo.toml Cargo.lock | wc -l)"
echo "== tree: commit $(git -C "$root" rev-parse --short HEAD), $changed changed or untracked files under src, shaders, data-tools, config, Cargo.*"
echo "== datasets"
dataset 1024
dataset 4096
small="$out/synth1024"
large="$out/synth4096"

# The same view over both datasets: 1–1.05 km above the datum (ground 100–750 m), pitched 55–60°
# down, so that even the top corners of a 60° × 16:9 view meet the lowest ground within 2–9.2 km.
write_path "$out/interior.toml" <<'EOF'
3000.0 3000.0 1000.0 45.0 -60.0
5000.0 3500.0 1000.0 80.0 -60.0
6500.0 5500.0 1050.0 10.0 -55.0
5500.0 7000.0 1000.0 300.0 -60.0
EOF
# The jump: 1 km above the datum, 30° down, from the south-west corner looking north-east to near
# the north-east corner looking south-west over fields (47 km apart); one key per frame.
jump_keys() {
    for ((i = 0; i < $1; i++)); do echo "2000.0 2000.0 1000.0 45.0 -30.0"; done
    for ((i = 0; i < $1; i++)); do echo "36000.0 34000.0 1000.0 225.0 -30.0"; done
}
jump_keys "$hold" | write_path "$out/jump.toml"
# A still camera over the middle of the small dataset, 60° down: the same view over both, nothing
# to stream after the first frames: rendering cost alone.
echo "5000.0 5000.0 1000.0 45.0 -60.0" | write_path "$out/still.toml"
jump_keys 20 | write_path "$out/jump_short.toml"

measure() {
    echo
    echo "== flights: $frames frames at $width × $height, $repeats run(s) per path and dataset"
    for path in default interior; do
        [[ $path == default ]] && file="$root/config/paths/default.toml" || file="$out/interior.toml"
        for ((r = 1; r <= repeats; r++)); do
            fly "$path-small-$r" "$small" "$file" "$frames" 0 "$width" "$height"
            fly "$path-large-$r" "$large" "$file" "$frames" 0 "$width" "$height"
        done
    done
    for ((r = 1; r <= repeats; r++)); do
        fly "still-small-$r" "$small" "$out/still.toml" 60 0 "$width" "$height"
        fly "still-large-$r" "$large" "$out/still.toml" 60 0 "$width" "$height"
    done
    fly jump "$large" "$out/jump.toml" "$((2 * hold))" 0 "$width" "$height"

    for path in default interior; do
        smalls=() larges=()
        for ((r = 1; r <= repeats; r++)); do
            smalls+=("$out/$path-small-$r/log.jsonl")
            larges+=("$out/$path-large-$r/log.jsonl")
        done
        echo
        if [[ $path == default ]]; then
            echo "######## path: config/paths/default.toml (the camera stays within 10 km; the view reaches past it)"
        else
            echo "######## path: interior.toml (the whole view within the small dataset: the same view over both)"
        fi
        python3 "$summary" compare --small "${smalls[@]}" --large "${larges[@]}"
    done
    smalls=() larges=()
    for ((r = 1; r <= repeats; r++)); do
        smalls+=("$out/still-small-$r/log.jsonl")
        larges+=("$out/still-large-$r/log.jsonl")
    done
    echo
    echo "######## still camera: still.toml, 60 frames, timings after the first 20"
    python3 "$summary" compare --brief --warmup 20 --small "${smalls[@]}" --large "${larges[@]}"
    echo
    echo "######## camera jump over synth4096 at $width × $height ($hold frames at each pose)"
    python3 "$summary" jump "$out/jump/log.jsonl" --jump-frame "$hold"
}
[[ "${IMAGES_ONLY:-0}" == 1 ]] || measure

echo
echo "== images (640 × 360) into $root/docs"
fly strip "$small" "$root/config/paths/default.toml" 240 40 640 360
i=0
for png in "$out"/strip/frame_*.png; do
    [[ $i -lt 6 ]] || break
    cp "$png" "$root/docs/flight_$i.png"
    echo "  docs/flight_$i.png <- $(basename "$png") ($(stat -c %s "$png") bytes)"
    i=$((i + 1))
done
fly jump_short "$large" "$out/jump_short.toml" 40 1 640 360
read -r jumped resolved < <(python3 "$summary" jump "$out/jump_short/log.jsonl" --jump-frame 20 --frames-only)
for pair in "before:$jumped" "after:$resolved"; do
    name="${pair%%:*}" frame="${pair#*:}"
    png="$(printf '%s/jump_short/frame_%04d.png' "$out" "$frame")"
    cp "$png" "$root/docs/flight_jump_$name.png"
    echo "  docs/flight_jump_$name.png <- frame $frame ($(stat -c %s "$png") bytes)"
done
