#!/usr/bin/env bash
# The GPU benchmark (issue 19): one run, a few minutes, one JSON. Made for a lent machine with an
# NVIDIA GPU and binaries built elsewhere; runs as it is on the software adapter too (CI runs it
# with a tiny frame count, tests/gpu_bench.rs).
#
#   scripts/gpu_bench.sh                     # writes out/gpu_bench/gpu_bench.json
#
# Steps: the synthetic default dataset (`terramp-data synth`, unless DATASET is given); `terramp
# profile` over its default path at 1920 × 1080 with the accurate preset and scripts/gpu_bench.toml
# (over 1 M seeds checked and 100 k drawn a frame), the trees drawn with IMPOSTORS, then the same
# with the seeds' depth prepass (`draw_seeds.depth_prepass`, off by default) on; the compute
# passes' criterion benches when BENCH_DIR holds their binaries (`cargo bench --no-run`: compact-*,
# seeds-*, tile_load_map-*). The JSON: the machine, the profile's whole summary (adapter and driver
# included), the prepass run's, and each bench's mean.
#
# Environment: BIN (target/release: terramp, terramp-data), TERRAMP / TERRAMP_DATA (the binaries
# themselves), DATASET, IMPOSTORS (data/trade/impostors), FRAMES (120), WARMUP (30), WIDTH × HEIGHT
# (1920 × 1080), PRESET (accurate), BENCH_DIR, BENCH_SECONDS (3: each bench's measurement time),
# OUT (out/gpu_bench).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${BIN:-${CARGO_TARGET_DIR:-target}/release}
TERRAMP=${TERRAMP:-$BIN/terramp}
TERRAMP_DATA=${TERRAMP_DATA:-$BIN/terramp-data}
FRAMES=${FRAMES:-120}
WARMUP=${WARMUP:-30}
WIDTH=${WIDTH:-1920}
HEIGHT=${HEIGHT:-1080}
PRESET=${PRESET:-accurate}
IMPOSTORS=${IMPOSTORS:-data/trade/impostors}
BENCH_SECONDS=${BENCH_SECONDS:-3}
OUT=${OUT:-out/gpu_bench}
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
mkdir -p "$OUT"
[ -x "$TERRAMP" ] || { echo "no terramp binary at $TERRAMP (set BIN or TERRAMP)" >&2; exit 1; }
[ -d "$IMPOSTORS" ] || { echo "no impostors at $IMPOSTORS: terramp-data bake (set IMPOSTORS)" >&2; exit 1; }
start=$(date +%s)

dataset_ms=0
if [ -z "${DATASET:-}" ]; then
  DATASET=$OUT/synthetic
  if ! "$TERRAMP" info --dataset "$DATASET" >/dev/null 2>&1; then
    [ -x "$TERRAMP_DATA" ] || { echo "no terramp-data at $TERRAMP_DATA to build $DATASET" >&2; exit 1; }
    t0=$(date +%s%N)
    "$TERRAMP_DATA" synth --out "$DATASET" >/dev/null
    dataset_ms=$((($(date +%s%N) - t0) / 1000000))
  fi
fi

profile() { # name, depth prepass (true/false)
  local settings=$OUT/settings-$1.toml
  sed "s|^\[draw_seeds\]|[draw_seeds]\nimpostors = \"$(realpath "$IMPOSTORS")\"\ndepth_prepass = $2|" \
    scripts/gpu_bench.toml >"$settings"
  echo "profile ($1): $FRAMES frames after $WARMUP at ${WIDTH}×${HEIGHT}, preset $PRESET, over $DATASET" >&2
  "$TERRAMP" profile --dataset "$DATASET" --frames "$FRAMES" --warmup "$WARMUP" --width "$WIDTH" \
    --height "$HEIGHT" --preset "$PRESET" --settings "$settings" --json "$OUT/$1.json" >"$OUT/$1.txt"
  cat "$OUT/$1.txt" >&2
}
profile profile false
profile profile_depth_prepass true

# Each bench binary's groups, measured briefly; criterion keeps each estimate in CRITERION_HOME.
benches=()
if [ -n "${BENCH_DIR:-}" ]; then
  export CRITERION_HOME=$OUT/criterion
  for name in tile_load_map seeds compact; do
    for exe in "$BENCH_DIR"/"$name"-*; do
      [ -x "$exe" ] && [ -f "$exe" ] || continue
      echo "bench: $(basename "$exe")" >&2
      "$exe" --bench --warm-up-time 1 --measurement-time "$BENCH_SECONDS" --noplot >"$OUT/bench-$name.txt" 2>&1 ||
        { tail -5 "$OUT/bench-$name.txt" >&2; exit 1; }
    done
  done
  while IFS= read -r estimates; do
    id=${estimates#"$CRITERION_HOME"/}
    id=${id%/new/estimates.json}
    mean=$(grep -o '"mean":{"confidence_interval":{[^}]*},"point_estimate":[0-9.e+-]*' "$estimates" | grep -o '[0-9.e+-]*$')
    benches+=("{\"id\": \"$id\", \"mean_ns\": $mean}")
  done < <(find "$CRITERION_HOME" -path '*/new/estimates.json' | sort)
fi

json=$OUT/gpu_bench.json
{
  printf '{\n  "schema": "terramp-gpu-bench/1",\n  "date": "%s",\n' "$(date -u +%FT%TZ)"
  printf '  "machine": "%s, %s cores",\n' "$(uname -srm)" "$(nproc)"
  printf '  "dataset_build_ms": %s,\n  "seconds": %s,\n' "$dataset_ms" "$(($(date +%s) - start))"
  printf '  "benches": [%s],\n' "$(IFS=,; echo "${benches[*]:-}")"
  printf '  "profile": '
  cat "$OUT/profile.json"
  printf ',\n  "profile_depth_prepass": '
  cat "$OUT/profile_depth_prepass.json"
  printf '\n}\n'
} >"$json"
echo "wrote $json in $(($(date +%s) - start)) s" >&2
