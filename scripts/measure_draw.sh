#!/usr/bin/env bash
# Drawing and profiling figures (issue: draw and profile): the demo (default synthetic dataset,
# impostors baked from ../shared/data/models on first use), then `terramp profile` with the seeds
# drawn over the default dataset and over nc/ (built into target/tmp when missing), then the
# seed_draw and compact benches. Needs ../shared/data. Usage: scripts/measure_draw.sh [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
frames="${1:-60}"
cargo build -q --release --workspace
bin=target/release/terramp
# The demo makes data/default and data/impostors when missing.
$bin demo --frames 2 --out target/tmp/demo-warm >/dev/null
nc=target/tmp/nc-profile
if ! $bin info --dataset "$nc" >/dev/null 2>&1; then
    data=../shared/data/nc
    target/release/terramp-data build --dem $data/elev_ned_30m.tif --imagery $data/landsat_multiband.tif \
        --bands 3,2,1 --landcover $data/landuse_r.tif --classes nc --out "$nc" >/dev/null
fi
settings=$(mktemp --suffix .toml)
printf '[draw_seeds]\nimpostors = "data/impostors"\n' >"$settings"
echo "## synthetic default dataset (default path)"
$bin profile --dataset data/default --frames "$frames" --warmup 10 --settings "$settings" 2>/dev/null
echo
echo "## nc/ (config/paths/nc.toml)"
$bin profile --dataset "$nc" --path config/paths/nc.toml --frames "$frames" --warmup 10 --settings "$settings" 2>/dev/null
rm -f "$settings"
echo
echo "## select + compact + draw, fixed camera (cargo bench --bench seed_draw)"
cargo bench -q --bench seed_draw 2>/dev/null | grep -E 'fixed camera|time:|^seed_passes'
