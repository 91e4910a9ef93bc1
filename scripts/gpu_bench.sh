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
# seeds-*, tile_load_map-*). The JSON, written by python3's json module: the machine, the
# profile's whole summary (adapter and driver included), the prepass run's, and each bench's mean.
#
# Environment: BIN (target/release: terramp, terramp-data), TERRAMP / TERRAMP_DATA (the binaries
# themselves), DATASET, IMPOSTORS (data/trade/impostors), FRAMES (120), WARMUP (30), WIDTH × HEIGHT
# (1920 × 1080), PRESET (accurate), BENCH_DIR, BENCHES (the bench binaries' names: tile_load_map
# seeds compact), BENCH_SECONDS (3: each bench's measurement time), OUT (out/gpu_bench).
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
BENCHES=${BENCHES:-tile_load_map seeds compact}
BENCH_SECONDS=${BENCH_SECONDS:-3}
OUT=${OUT:-out/gpu_bench}
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
mkdir -p "$OUT"
[ -x "$TERRAMP" ] || { echo "no terramp binary at $TERRAMP (set BIN or TERRAMP)" >&2; exit 1; }
[ -d "$IMPOSTORS" ] || { echo "no impostors at $IMPOSTORS: terramp-data bake (set IMPOSTORS)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "gpu_bench.sh writes its JSON with python3: install it" >&2; exit 1; }
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
export CRITERION_HOME=$OUT/criterion
rm -rf "$CRITERION_HOME"
if [ -n "${BENCH_DIR:-}" ]; then
  for name in $BENCHES; do
    for exe in "$BENCH_DIR"/"$name"-*; do
      [ -x "$exe" ] && [ -f "$exe" ] || continue
      echo "bench: $(basename "$exe")" >&2
      "$exe" --bench --warm-up-time 1 --measurement-time "$BENCH_SECONDS" --noplot >"$OUT/bench-$name.txt" 2>&1 ||
        { tail -5 "$OUT/bench-$name.txt" >&2; exit 1; }
    done
  done
fi

# The JSON: each bench's id (its folder under CRITERION_HOME) and mean from its estimates.
json=$OUT/gpu_bench.json
OUT=$OUT DATASET_MS=$dataset_ms START=$start python3 - "$json" <<'EOF'
import datetime, json, os, pathlib, sys, time

out, home = pathlib.Path(os.environ["OUT"]), pathlib.Path(os.environ["CRITERION_HOME"])
benches = []
for estimates in sorted(home.glob("**/new/estimates.json")):
    mean_ns = json.loads(estimates.read_text())["mean"]["point_estimate"]
    benches.append({"id": estimates.parent.parent.relative_to(home).as_posix(), "mean_ns": mean_ns})
uname = os.uname()
document = {
    "schema": "terramp-gpu-bench/1",
    "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    "machine": f"{uname.sysname} {uname.release} {uname.machine}, {len(os.sched_getaffinity(0))} cores",
    "dataset_build_ms": int(os.environ["DATASET_MS"]),
    "seconds": int(time.time()) - int(os.environ["START"]),
    "benches": benches,
    "profile": json.loads((out / "profile.json").read_text()),
    "profile_depth_prepass": json.loads((out / "profile_depth_prepass.json").read_text()),
}
pathlib.Path(sys.argv[1]).write_text(json.dumps(document, indent=2) + "\n")
EOF
echo "wrote $json in $(($(date +%s) - start)) s" >&2
