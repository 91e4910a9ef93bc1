#!/usr/bin/env bash
# The scale run of partitioned builds (docs/building.md): the synthetic dataset of SIZE samples per
# side (or GeoTIFF INPUTS, `build`'s arguments) built as one process, then as PARTS partitions on a
# Dask LocalCluster of WORKERS workers; prints wall time, peak RSS per job and bytes, and checks the
# two datasets are the same bytes.
#
#   SIZE=8192 PARTS=8 WORKERS=2 scripts/partitioned_scale.sh
#   INPUTS="--dem $PWD/../shared/data/globe/globe_g_30arcsec.tif" PARTS=8 scripts/partitioned_scale.sh
#
# Needs a release build (cargo build --release -p terramp-data-tools) and .venv-dask
# (python3 -m venv .venv-dask && .venv-dask/bin/pip install -r scripts/requirements-dask.txt).
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${SIZE:-8192}
PARTS=${PARTS:-8}
WORKERS=${WORKERS:-2}
BIN=${BIN:-${CARGO_TARGET_DIR:-target}/release/terramp-data}
INPUTS=${INPUTS:-}
if [ -n "$INPUTS" ]; then
  read -ra inputs <<<"$INPUTS"
  single=(build "${inputs[@]}") planned=("${inputs[@]}") what="build $INPUTS"
  OUT=${OUT:-out/partitioned-geotiff}
else
  single=(synth --size "$SIZE") planned=(--synth-size "$SIZE") what="synthetic --size $SIZE"
  OUT=${OUT:-out/partitioned-$SIZE}
fi
PYTHON=${PYTHON:-.venv-dask/bin/python}
[ -x "$BIN" ] || { echo "no $BIN: cargo build --release -p terramp-data-tools" >&2; exit 1; }
[ -x "$PYTHON" ] || { echo "no $PYTHON: see the header of $0" >&2; exit 1; }
rm -rf "$OUT"
mkdir -p "$OUT"

measure() { # label, command...: wall seconds and peak RSS (MiB) of the command and its children
  local label=$1
  shift
  /usr/bin/time -f "%e %M" -o "$OUT/time.txt" "$@" >"$OUT/$label.log" 2>&1
  read -r wall kib <"$OUT/time.txt"
  printf '%-28s %8.1f s  peak RSS %6.0f MiB\n' "$label" "$wall" "$((kib / 1024))"
}

echo "$what on $(nproc) cores; $PARTS partitions on $WORKERS Dask workers"
measure "single process" "$BIN" "${single[@]}" --out "$OUT/single"
measure "plan (scans)" "$BIN" plan "${planned[@]}" --partitions "$PARTS" --out "$OUT/plan.toml"
measure "dask: jobs + merge" "$PYTHON" scripts/dask_build.py --plan "$OUT/plan.toml" --out "$OUT/merged" \
  --local "$WORKERS" --terramp-data "$BIN"
grep -h "partition .* built in\|merged" "$OUT/dask: jobs + merge.log" | sed 's/^dask: //; s/ (elapsed.*//'
echo "receipts (per job: seconds, peak RSS MiB):"
for r in "$OUT"/plan.parts/part-*/done.toml; do
  awk -F' = ' '/seconds|peak_rss_mib|partition/ {printf "%s=%s ", $1, $2} END {print ""}' "$r"
done
du -sb "$OUT/single" "$OUT/merged" "$OUT/plan.parts" | awk '{printf "%-40s %8.1f MB\n", $2, $1 / 1e6}'
for f in "$OUT"/single/*; do
  cmp -s "$f" "$OUT/merged/$(basename "$f")" || { echo "DIFFERS: $(basename "$f")"; exit 1; }
done
echo "merged dataset equals the single-process build, byte for byte"
