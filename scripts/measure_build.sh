#!/usr/bin/env bash
# Builds the `nc/` and `globe/` datasets and synthesizes the default (size 1024) dataset with a
# release `terramp-data`, and prints, for each, the wall time, the peak resident memory (from GNU
# time's maximum RSS) and the dataset's size on disk. SYNTH_SIZES="1024 4096" adds sizes.
#
# Usage: scripts/measure_build.sh [OUT_DIR]   (default: a fresh temporary folder, removed after)
# Needs GNU time at /usr/bin/time (Debian: apt-get install time) and ../shared/data.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
data="$root/../shared/data"
[[ -d "$data" ]] || { echo "no shared data at $data" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "GNU time is missing: apt-get install time" >&2; exit 1; }

if [[ $# -ge 1 ]]; then
    out="$1"
    mkdir -p "$out"
else
    out="$(mktemp -d "${TMPDIR:-/tmp}/terramp-measure.XXXXXX")"
    trap 'rm -rf "$out"' EXIT
fi

cargo build --release --quiet -p terramp-data-tools --manifest-path "$root/Cargo.toml"
bin="$root/target/release/terramp-data"

measure() {
    local name="$1"
    shift
    local log="$out/$name.time"
    /usr/bin/time -v -o "$log" "$bin" "$@" --out "$out/$name" >"$out/$name.log"
    local wall rss_kib bytes
    wall="$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log")"
    rss_kib="$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")"
    bytes="$(du -sb "$out/$name" | cut -f1)"
    awk -v n="$name" -v w="$wall" -v r="$rss_kib" -v b="$bytes" \
        'BEGIN { printf "%-6s wall %-8s peak RSS %6.1f MiB   dataset %7.1f MiB\n", n, w, r / 1024, b / 1048576 }'
    sed 's/^/       /' "$out/$name.log"
}

measure nc build --dem "$data/nc/elev_ned_30m.tif" --imagery "$data/nc/landsat_multiband.tif" --bands 3,2,1 \
    --landcover "$data/nc/landuse_r.tif" --classes nc
measure globe build --dem "$data/globe/globe_g_30arcsec.tif"
for size in ${SYNTH_SIZES:-1024}; do
    measure "synth$size" synth --size "$size"
done
