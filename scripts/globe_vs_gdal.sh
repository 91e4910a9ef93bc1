#!/usr/bin/env bash
# GLOBE built side by side on this machine (docs/building.md): `terramp-data build` against GDAL's
# own streamable pyramid of the same DEM (a COG, int16, DEFLATE with a predictor, overviews),
# ROUNDS rounds alternating the two, each timed with GNU time: wall, user + system CPU, peak RSS,
# bytes written. STEPS lists the `--height-step-m` values terramp builds with (each one a dataset);
# the first is the one the rounds time.
#
#   ROUNDS=3 STEPS="0.25 0 0.5 1" scripts/globe_vs_gdal.sh [OUT_DIR]
#
# Needs a release build (cargo build --release -p terramp-data-tools), gdalwarp (apt-get install
# gdal-bin), GNU time at /usr/bin/time, bc, and ../shared/data.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dem="$root/../shared/data/globe/globe_g_30arcsec.tif"
bin=${BIN:-$root/target/release/terramp-data}
ROUNDS=${ROUNDS:-3}
read -r -a steps <<<"${STEPS:-0.25}"
[[ -f "$dem" ]] || { echo "no GLOBE DEM at $dem" >&2; exit 1; }
[[ -x "$bin" ]] || { echo "no $bin: cargo build --release -p terramp-data-tools" >&2; exit 1; }
command -v gdalwarp >/dev/null || { echo "no gdalwarp: apt-get install gdal-bin" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "no GNU time: apt-get install time" >&2; exit 1; }
if [[ $# -ge 1 ]]; then
  out="$1"
  mkdir -p "$out"
else
  out="$(mktemp -d "${TMPDIR:-/tmp}/globe-vs-gdal.XXXXXX")"
  trap 'rm -rf "$out"' EXIT
fi

# The issue's GDAL command: the dataset's own frame (terramp's local azimuthal equidistant frame
# for a DEM in degrees, centred on its extent) and its spacing.
gdal_cog() {
  rm -f "$out/globe.cog.tif"
  gdalwarp -q -multi -wo NUM_THREADS=ALL_CPUS -t_srs '+proj=aeqd +lat_0=25 +lon_0=45' -tr 923.1 923.1 \
    -r bilinear -of COG -co COMPRESS=DEFLATE -co PREDICTOR=2 -co OVERVIEWS=AUTO "$dem" "$out/globe.cog.tif"
}
terramp_build() { # step
  "$bin" build --dem "$dem" --height-step-m "$1" --out "$out/globe-$1"
}

export dem bin out
export -f gdal_cog terramp_build

measure() { # label, bytes-path, command...
  local label=$1 path=$2
  shift 2
  /usr/bin/time -f "%e %U %S %M" -o "$out/time.txt" "$@" >"$out/last.log" 2>&1 || {
    cat "$out/last.log" >&2
    exit 1
  }
  read -r wall user sys kib <"$out/time.txt"
  local bytes
  bytes=$(du -sb "$path" | cut -f1)
  printf '%-26s wall %6.1f s  cpu %6.1f s  peak RSS %5d MiB  %7.1f MB (%6.1f MiB)\n' \
    "$label" "$wall" "$(echo "$user + $sys" | bc)" "$((kib / 1024))" \
    "$(echo "$bytes / 1000000" | bc -l)" "$(echo "$bytes / 1048576" | bc -l)"
}

echo "GLOBE tile G ($(nproc) cores): $ROUNDS rounds, terramp with --height-step-m ${steps[0]}"
for round in $(seq "$ROUNDS"); do
  measure "round $round: gdalwarp COG" "$out/globe.cog.tif" bash -c gdal_cog
  measure "round $round: terramp ${steps[0]}" "$out/globe-${steps[0]}" bash -c "terramp_build ${steps[0]}"
done
grep -h "heights:" "$out/last.log" || true
for step in "${steps[@]:1}"; do
  measure "terramp --height-step-m $step" "$out/globe-$step" bash -c "terramp_build $step"
done
echo "per pack (bytes):"
for d in "$out"/globe-*; do
  printf '  %-12s' "$(basename "$d")"
  for p in "$d"/*.pack; do printf ' %s %d' "$(basename "$p")" "$(stat -c %s "$p")"; done
  echo
done
