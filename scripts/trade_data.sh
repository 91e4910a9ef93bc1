# Sourced by scripts/trade.sh and scripts/texcells_truth.sh (needs $root, $data and $shared, the
# release binaries built): builds the datasets into $data (each reused while `terramp info` reads
# it): nc/ (DEM, Landsat bands 3,2,1, land use) and zion/ (DEM, NLCD) as data-tools/tests/support
# builds them, and the synthetic default (`synth --size 1024`); bakes the 11 shared models into
# $data/impostors (those missing or of an older format) and writes $trees, a settings layer that points
# `draw_seeds.impostors` at them.
terramp="${CARGO_TARGET_DIR:-$root/target}/release/terramp"
terramp_data="${CARGO_TARGET_DIR:-$root/target}/release/terramp-data"

# build NAME ARGS...: a dataset, unless a readable one is already there.
build() {
    local name="$1"
    shift
    if "$terramp" info --dataset "$data/$name" >/dev/null 2>&1; then
        echo "dataset $name: reusing $data/$name" >&2
    else
        echo "dataset $name: building into $data/$name" >&2
        "$@" --out "$data/$name" >/dev/null
    fi
}
build nc "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" --imagery "$shared/nc/landsat_multiband.tif" \
    --bands 3,2,1 --landcover "$shared/nc/landuse_r.tif" --classes nc
build zion "$terramp_data" build --dem "$shared/zion/dem_utm12n_30m.tif" \
    --landcover "$shared/zion/nlcd_utm12n_30m.tif" --classes nlcd
build synthetic "$terramp_data" synth --size 1024

impostors="$data/impostors"
models=(Birch_1 Birch_4 BushBerries_1 Bush_1 DeadTree_1 Pine_1 Pine_3 Rock_1 Rock_Moss_1 Tree_1 Tree_3)
args=()
for m in "${models[@]}"; do args+=(--model "$shared/models/$m.glb"); done
# Only what is missing or of an older format.
"$terramp_data" bake "${args[@]}" --out "$impostors" --texels 256 --missing >/dev/null
trees="$data/trees.toml"
printf '# Written by scripts/trade.sh: draw the seeds with the baked impostors.\n[draw_seeds]\nimpostors = "%s"\n' \
    "$(cd "$impostors" && pwd)" >"$trees"

