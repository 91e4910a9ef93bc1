#!/usr/bin/env bash
# Every image in docs/, made again from the code, on whatever adapter wgpu picks (lavapipe here).
# One maker per figure; the table below lists every image the docs show and the maker that writes
# it (`tests/docs_images.rs` checks that every image docs/*.md and README.md reference exists and
# is listed here, and that every image under docs/ is listed and referenced).
#
#   scripts/docs_images.sh                 # every maker marked `short` (about an hour on 2 cores)
#   scripts/docs_images.sh nc light        # only these makers
#   scripts/docs_images.sh --long          # also the long ones (soaks, sweeps: many hours)
#   scripts/docs_images.sh --list          # the table
#
# Makers marked `shared` read ../shared/data (nc/, zion/, rainier/, models/, globe/). The datasets
# and impostors are built into DATA_DIR (data/trade, as scripts/trade.sh builds them, reused while
# current); scratch files go to OUT (/tmp/terramp-docs-images). Needs: the release build (made
# here); python3 with Pillow for `slicings_tree1`, `wind` and the soaks (without it, Pillow is
# installed from PyPI into .venv-docs, scripts/requirements-docs.txt); Xvfb, xdotool and xwd for
# `viewer` (apt-get install xvfb xdotool x11-apps).
#
# A new figure in docs/ gets a maker here and a row in the table, in the same commit.
set -euo pipefail

# image                                   maker              needs    cost
table="
docs/nc.png                               nc                 shared   short
docs/rainier.png                          rainier            shared   short
docs/synthetic.png                        synthetic          -        short
docs/demo_generated.png                   demo               -        short
docs/impostor_pine.png                    impostor_pine      shared   short
docs/nc_trees.png                         nc_trees           shared   short
docs/imagery_blocks_synthetic.png         imagery_blocks     shared   short
docs/imagery_blocks_nc.png                imagery_blocks     shared   short
docs/cloud_shadows.png                    light              shared   short
docs/crown_shading.png                    light              shared   short
docs/seeds_border.png                     seeds_border       shared   short
docs/slicings_tree1.png                   slicings_tree1     shared   short
docs/slicings_edge.png                    slicings_edge      shared   short
docs/slicings_orbit.png                   slicings_figures   shared   short
docs/slicings_three_ways.png              slicings_figures   shared   short
docs/texcells_nc.png                      texcells           shared   short
docs/texcells_nc_2km.png                  texcells           shared   short
docs/texcells_switch.png                  texcells           shared   short
docs/texcells_zion_rim.png                texcells           shared   short
docs/trees_health.png                     trees_health       -        short
docs/continuous_lod_compare.png           continuous_lod     -        short
docs/truth_vs_accurate.png                truth_vs_accurate  -        short
docs/viewer_nc.png                        viewer             shared   short
docs/wind_strip.png                       wind               shared   short
docs/photo_nc.png                         photo              shared   long
docs/earth_globe_12km.png                 earth              shared   short
docs/earth_nc_descent.png                 earth_nc           shared   short
docs/earth_globe_orbit.png                earth_orbit        shared   short
docs/atmosphere_sky.png                   atmosphere         shared   short
docs/display_curves.png                   display            shared   short
docs/flight_0.png                         streaming          -        long
docs/flight_1.png                         streaming          -        long
docs/flight_2.png                         streaming          -        long
docs/flight_3.png                         streaming          -        long
docs/flight_4.png                         streaming          -        long
docs/flight_5.png                         streaming          -        long
docs/flight_jump_before.png               streaming          -        long
docs/flight_jump_after.png                streaming          -        long
docs/soak_globe.png                       soak_globe         shared   long
docs/soak_nc.png                          soak_nc            shared   long
docs/soak_nc_growth.png                   soak_nc_growth     shared   long
docs/soak_nc_there_and_back.png           soak_nc_there_and_back shared long
docs/trade/synthetic/trade.png            trade              shared   long
docs/trade/nc/trade.png                   trade              shared   long
docs/trade/zion/trade.png                 trade              shared   long
docs/trade/continuous_lod/trade.png       trade_continuous_lod shared long
docs/trade/slicings/trade.png             trade_slicings     shared   long
docs/texcells/trade.png                   trade_texcells     shared   long
"

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
unset RUST_BACKTRACE
shared="$root/../shared/data"
data="${DATA_DIR:-data/trade}"
out="${OUT:-/tmp/terramp-docs-images}"

rows() { grep -v '^\s*$' <<<"$table"; }
makers_of() { rows | awk -v cost="$1" '$4 == cost || cost == "any" { print $2 }' | awk '!seen[$0]++'; }

long=0 wanted=()
for arg in "$@"; do
    case "$arg" in
        --list) rows; exit 0 ;;
        --long) long=1 ;;
        -*) echo "docs_images.sh: unknown option $arg (--list, --long)" >&2; exit 2 ;;
        *) makers_of any | grep -qx "$arg" || { echo "docs_images.sh: no maker $arg (--list shows them)" >&2; exit 2; }
           wanted+=("$arg") ;;
    esac
done
if [[ ${#wanted[@]} -eq 0 ]]; then
    mapfile -t wanted < <(makers_of short)
    [[ $long == 1 ]] && mapfile -t -O "${#wanted[@]}" wanted < <(makers_of long)
fi
for maker in "${wanted[@]}"; do
    if rows | awk -v m="$maker" '$2 == m && $3 == "shared"' | grep -q . && [[ ! -d "$shared" ]]; then
        echo "docs_images.sh: $maker needs $shared (the shared data beside the repository)" >&2
        exit 1
    fi
done

mkdir -p "$out" "$data"
cargo build --release --workspace -q
terramp="${CARGO_TARGET_DIR:-$root/target}/release/terramp"
terramp_data="${CARGO_TARGET_DIR:-$root/target}/release/terramp-data"
compose() { "$terramp_data" compose "$@"; }

# python3 with Pillow first on PATH (the scripts the makers call run `python3`).
pillow() {
    python3 -c 'import PIL' 2>/dev/null && return
    if [[ ! -x .venv-docs/bin/python ]] || ! .venv-docs/bin/python -c 'import PIL' 2>/dev/null; then
        python3 -m venv .venv-docs
        .venv-docs/bin/pip install -q -r scripts/requirements-docs.txt
    fi
    export PATH="$root/.venv-docs/bin:$PATH"
}

# The trade's datasets (nc, zion, the synthetic default) and the 11 shared models' impostors.
trade_data_ready=0
trade_data() {
    [[ $trade_data_ready == 1 ]] && return
    # shellcheck source=scripts/trade_data.sh
    source scripts/trade_data.sh
    trade_data_ready=1
}

# A settings layer: layer NAME LINES... (each a TOML line) into $out/NAME.toml; echoes its path.
layer() {
    local name="$1"
    shift
    printf '%s\n' "# Written by scripts/docs_images.sh." "$@" >"$out/$name.toml"
    echo "$out/$name.toml"
}

# The nc table's forest samples (texcells) beside the trade's impostors, as texcells_truth.sh does.
forest_ready=0
forest() {
    [[ $forest_ready == 1 ]] && return
    trade_data
    forest="$data/forest"
    if [[ ! -d "$forest/texcells/5" ]]; then
        rm -rf "$forest"
        cp -r "$impostors" "$forest"
        "$terramp_data" bake --classes nc --models "$shared/models" --out "$forest" >/dev/null
    fi
    forest_ready=1
}

# The shared models baked with their slicings (6 × 5), as slicings_trade.sh does (at 1024 texels).
sliced_ready=0
sliced() {
    [[ $sliced_ready == 1 ]] && return
    trade_data
    sliced="$data/sliced-1024"
    if [[ ! -f "$sliced/Tree_1/slicing_mip0.png" ]]; then
        local args=()
        for m in "${models[@]}"; do args+=(--model "$shared/models/$m.glb"); done
        "$terramp_data" bake "${args[@]}" --out "$sliced" --texels 1024 --slicings 6x5 >/dev/null
    fi
    sliced_ready=1
}

# The demo's dataset and generated trees (data/default, data/impostors), as `terramp demo` makes them.
demo_ready=0
demo_data() {
    [[ $demo_ready == 1 ]] && return
    rm -rf "$out/demo"
    "$terramp" demo --out "$out/demo" >"$out/demo.log"
    demo_ready=1
}

render() { "$terramp" render "$@" >/dev/null; }

# views NAME DATASET CAMERA WIDTHxHEIGHT LAYER...: the view rendered once per settings layer, into
# $out/NAME_<layer>.png; the files, in order, are left in the array `shots`.
views() {
    local name="$1" dataset="$2" camera="$3" size="$4" layer
    shift 4
    shots=()
    for layer in "$@"; do
        shots+=("$out/${name}_$(basename "$layer" .toml).png")
        render --dataset "$dataset" --camera "$camera" --width "${size%x*}" --height "${size#*x}" \
            --settings "$layer" --out "${shots[-1]}"
    done
}

make_nc() {
    trade_data
    render --dataset "$data/nc" --camera 634000,212500,4200,5,-32 --width 960 --height 540 --preset accurate \
        --out docs/nc.png
}

make_rainier() {
    if ! "$terramp" info --dataset "$data/rainier" >/dev/null 2>&1; then
        "$terramp_data" build --dem "$shared/rainier/mt_rainier_90m.tif" --out "$data/rainier" >/dev/null
    fi
    render --dataset "$data/rainier" --camera -8000,16000,2600,337,-3 --width 960 --height 540 --preset accurate \
        --out docs/rainier.png
}

make_synthetic() {
    # The embedded default's ground alone (no seeds), over the fields towards the lake.
    demo_data
    render --dataset data/default --camera 4000,4500,350,50,-8 --width 1280 --height 720 \
        --settings "$(layer ground '[seeds]' 'density_scale = 0.0')" --out docs/synthetic.png
}

make_demo() {
    demo_data
    cp "$out/demo/frame_0009.png" docs/demo_generated.png
}

make_impostor_pine() {
    "$terramp_data" bake --model "$shared/models/Pine_1.glb" --out "$out/pine" >/dev/null
    compose --checker 16 --gap 8 --out docs/impostor_pine.png "$out"/pine/Pine_1/lod{0,1,2}_mip1.png
}

make_nc_trees() {
    cargo test --release -q -p terramp-data-tools --test draw_seeds -- --ignored >/dev/null
}

make_imagery_blocks() {
    trade_data
    local format
    for format in bc7 bc1; do
        "$terramp" info --dataset "$data/synthetic_$format" >/dev/null 2>&1 ||
            "$terramp_data" synth --size 1024 --imagery-format "$format" --out "$data/synthetic_$format" >/dev/null
        "$terramp" info --dataset "$data/nc_$format" >/dev/null 2>&1 ||
            "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" --imagery "$shared/nc/landsat_multiband.tif" \
                --bands 3,2,1 --landcover "$shared/nc/landuse_r.tif" --classes nc --imagery-format "$format" \
                --out "$data/nc_$format" >/dev/null
    done
    FRAMES=8 OUT="$out/blocks" cargo bench -q --bench imagery_formats -- config/paths/default.toml \
        "$data/synthetic" "$data/synthetic_bc7" "$data/synthetic_bc1" >/dev/null
    FRAMES=8 OUT="$out/blocks" cargo bench -q --bench imagery_formats -- config/paths/nc.toml \
        "$data/nc" "$data/nc_bc7" "$data/nc_bc1" >/dev/null
    cp "$out/blocks/synthetic_crops.png" docs/imagery_blocks_synthetic.png
    cp "$out/blocks/nc_crops.png" docs/imagery_blocks_nc.png
}

make_light() {
    forest
    local impostors_line="impostors = \"$(cd "$forest" && pwd)\""
    local clear cloudy flat shaded
    clear=$(layer clear '[draw_seeds]' "$impostors_line")
    cloudy=$(layer cloudy '[draw_seeds]' "$impostors_line" '[clouds]' 'coverage = 0.4')
    views clouds "$data/nc" 631000,215500,2000,40,-12 960x540 "$clear" "$cloudy"
    compose --columns 1 --scale 0.75 --out docs/cloud_shadows.png "${shots[@]}"
    # Crown shading 0.5 on every species of the nc table.
    awk '/^\[\[species\]\]/ { print; print "crown_shading = 0.5"; next } !/^crown_shading/ { print }' \
        config/classes/nc.toml >"$out/nc_shaded.toml"
    flat=$(layer flat '[draw_seeds]' "$impostors_line")
    shaded=$(layer shaded '[seeds]' "class_table = \"$out/nc_shaded.toml\"" '[draw_seeds]' "$impostors_line")
    views crowns "$data/nc" 636500,216500,125,20,-6 960x540 "$flat" "$shaded"
    compose --columns 1 --scale 0.75 --out docs/crown_shading.png "${shots[@]}"
}

make_seeds_border() {
    rm -rf "$out/spacing" && mkdir -p "$out/spacing"
    TERRAMP_SPACING_PNG="$out/spacing" cargo test --release -q -p terramp-data-tools --test seed_spacing >/dev/null
    compose --scale 0.5 --gap 6 --background 90,90,90 --out docs/seeds_border.png "$out"/spacing/seeds_border_{nc,zion}.png
}

make_slicings_tree1() {
    pillow
    "$terramp_data" bake --model "$shared/models/Tree_1.glb" --out "$out/sl" --slicings 6x5 >/dev/null
    python3 scripts/slices_figure.py "$out/sl/Tree_1" 0 docs/slicings_tree1.png
}

make_slicings_edge() {
    sliced
    local impostors_line="impostors = \"$(cd "$sliced" && pwd)\""
    local lod1_from_0='reach_m = [0.0, 1000.0, 1400.0, 3000.0]'
    views edge "$data/nc" 636500,216500,125,20,-6 960x540 "$(layer meshes '[draw_seeds]' "$impostors_line")" \
        "$(layer clouds '[draw_seeds]' "$impostors_line" "$lod1_from_0")" \
        "$(layer slices '[draw_seeds]' "$impostors_line" "$lod1_from_0" 'slicings = true')"
    compose --columns 1 --scale 0.75 --out docs/slicings_edge.png "${shots[@]}"
}

make_slicings_figures() {
    cargo test -q --test slicings -- --ignored >/dev/null
    cargo test -q --test slicings_views -- --ignored >/dev/null
}

make_texcells() {
    forest
    # texcells_nc.png: the frames of data-tools/tests/texcells.rs (written to its target tmpdir).
    cargo test --release -q -p terramp-data-tools --test texcells nc_texcells_cover_the_far_forest_and_no_water \
        >/dev/null
    local shots="${CARGO_TARGET_DIR:-$root/target}/tmp"
    compose --columns 1 --gap 0 --out docs/texcells_nc.png "$shots"/texcells_nc_{without,with}.png
    local impostors_line="impostors = \"$(cd "$forest" && pwd)\""
    local with without
    without=$(layer without '[draw_seeds]' "$impostors_line" '[texcells]' 'reach_m = 0.0')
    with=$(layer with '[draw_seeds]' "$impostors_line")
    # The forest past the last clouds: a 640 × 200 crop at 1.5×.
    views switch "$data/nc" 636500,216500,350,20,-8 1280x720 "$without" "$with"
    compose --columns 1 --crop 320,230,640,200 --scale 1.5 --gap 4 --out docs/texcells_switch.png "${shots[@]}"
    views nc2km "$data/nc" 631000,215500,2000,40,-12 1280x720 "$without" "$with"
    compose --columns 1 --scale 0.75 --gap 4 --out docs/texcells_nc_2km.png "${shots[@]}"
    views zion "$data/zion" 316900,4136000,2600,0,-6 1280x720 "$without" "$with"
    compose --columns 1 --scale 0.75 --gap 4 --out docs/texcells_zion_rim.png "${shots[@]}"
}

# The photograph, before the colour follow-up, after it, and after it on nc built with its
# vegetation index (--nir-band 4): nc's forest from 3 km straight down, 1.5 km at 45° and 300 m at
# 30°. "Before" is the release build of c1e844b (the last commit before it), built once in a
# worktree of its own (long: a second release build), or BEFORE_BIN if given.
make_photo() {
    forest
    local trees before_bin="${BEFORE_BIN:-}"
    trees=$(layer photo_trees '[draw_seeds]' "impostors = \"$(cd "$forest" && pwd)\"")
    if [[ -z $before_bin ]]; then
        local tree="$out/before-c1e844b"
        [[ -d $tree ]] || git worktree add --detach "$tree" c1e844b >/dev/null
        (cd "$tree" && CARGO_TARGET_DIR="$out/before-target" cargo build --release -q --bin terramp)
        before_bin="$out/before-target/release/terramp"
    fi
    if [[ ! -f "$data/nc_ndvi/manifest.toml" ]]; then
        "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" --imagery "$shared/nc/landsat_multiband.tif" \
            --bands 3,2,1 --nir-band 4 --landcover "$shared/nc/landuse_r.tif" --classes nc --out "$data/nc_ndvi" \
            >/dev/null
    fi
    local rows=() view name pose
    for view in 3km:637500,221750,3000,0,-89 1500m_45:637500,221750,1600,0,-45 300m_30:637500,221750,400,0,-30; do
        name=${view%%:*} pose=${view#*:}
        "$before_bin" render --dataset "$data/nc" --camera "$pose" --width 640 --height 640 --settings "$trees" \
            --out "$out/photo_before_$name.png" >/dev/null
        "$terramp" photo --dataset "$data/nc" --camera "$pose" --width 640 --height 640 --settings "$trees" \
            --out "$out/photo_after_$name" >/dev/null
        "$terramp" photo --dataset "$data/nc_ndvi" --camera "$pose" --width 640 --height 640 --settings "$trees" \
            --out "$out/photo_ndvi_$name" >/dev/null
        rows+=("$out/photo_after_$name/photograph.png" "$out/photo_before_$name.png" \
            "$out/photo_after_$name/amplified.png" "$out/photo_ndvi_$name/amplified.png")
    done
    compose --columns 4 --scale 0.5 --gap 4 --out docs/photo_nc.png "${rows[@]}"
}

# GLOBE's tile from 12 km up over its centre, looking 3° down: on the Earth, then as the flat
# sheet (docs/earth.md). Built into DATA_DIR/globe (as scripts/soak.sh does) where that build
# predates the manifest's [earth].
make_earth() {
    local globe="$data/globe" flat
    if ! grep -q '^\[earth\]' "$globe/manifest.toml" 2>/dev/null; then
        "$terramp_data" build --dem "$shared/globe/globe_g_30arcsec.tif" --out "$globe" >/dev/null
    fi
    flat=$(layer earth_flat '[render]' 'curved_earth = false')
    "$terramp" render --dataset "$globe" --camera 0,0,12000,0,-3 --width 640 --height 360 \
        --out "$out/earth_round.png" >/dev/null
    "$terramp" render --dataset "$globe" --camera 0,0,12000,0,-3 --width 640 --height 360 --settings "$flat" \
        --out "$out/earth_flat.png" >/dev/null
    compose --columns 1 --gap 4 --out docs/earth_globe_12km.png "$out/earth_round.png" "$out/earth_flat.png"
}

# nc on the Earth from 10 km, 1 km and 10 m above the ground at Raleigh (the trade's trees and
# forest samples), heading 210° (Raleigh lies near its north-east corner): the dataset alone on the Earth, the horizon at its curved edge,
# the trees on their local verticals (docs/earth.md). nc is the trade's where its manifest records
# where it lies; one built before that gets nc_earth beside it, as scripts/earth_cost.sh builds it.
make_earth_nc() {
    forest
    local nc="$data/nc" trees shots=() pose
    if ! grep -q '^\[earth\]' "$nc/manifest.toml"; then
        nc="$data/nc_earth"
        [[ -f $nc/manifest.toml ]] || "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" \
            --imagery "$shared/nc/landsat_multiband.tif" --bands 3,2,1 \
            --landcover "$shared/nc/landuse_r.tif" --classes nc --out "$nc" >/dev/null
    fi
    trees=$(layer earth_nc_trees '[draw_seeds]' "impostors = \"$(cd "$forest" && pwd)\"")
    for pose in 10000,-55 1000,-25 10,-3; do
        "$terramp" render --dataset "$nc" --camera "lonlat-ground:-78.66,35.77,${pose%,*},210,${pose#*,}" \
            --width 640 --height 360 --settings "$trees" --out "$out/earth_nc_${pose%,*}.png" >/dev/null
        shots+=("$out/earth_nc_${pose%,*}.png")
    done
    compose --columns 1 --scale 0.75 --gap 4 --out docs/earth_nc_descent.png "${shots[@]}"
}

# GLOBE's tile from orbit, seen through the air (docs/atmosphere.md): from 20,000 km over its
# centre (a patch of the sphere), from 2,000 km over 5° N 30° E looking north-east 30° down (its
# limb) and from 100 km over the Himalaya looking north 35° down (docs/earth.md). GLOBE built as
# make_earth builds it.
make_earth_orbit() {
    local globe="$data/globe" shots=() pose
    if ! grep -q '^\[earth\]' "$globe/manifest.toml" 2>/dev/null; then
        "$terramp_data" build --dem "$shared/globe/globe_g_30arcsec.tif" --out "$globe" >/dev/null
    fi
    for pose in 45,25,20000000,0,-90 30,5,2000000,45,-30 86.9,27.2,100000,0,-35; do
        "$terramp" render --dataset "$globe" --camera "lonlat:$pose" --width 640 --height 360 \
            --out "$out/earth_orbit_${pose//,/_}.png" >/dev/null
        shots+=("$out/earth_orbit_${pose//,/_}.png")
    done
    compose --columns 1 --scale 0.75 --gap 4 --out docs/earth_globe_orbit.png "${shots[@]}"
}

# The air from the atmosphere pass (docs/atmosphere.md): nc from 300 m looking west, level, with
# the trade's trees, the sun in the west at 40°, 1° and −4° (day, sunset, dusk; EV100 15, 12, 8), the ground and the
# trees lit by the sun and the sky through the air and seen through it; the same at 40° without
# aerial perspective; nc from 10 km looking west 50° down,
# the sun at 20°; zion from 10 km over its southern edge looking north 30° down, the sun in the
# west-south-west at 40° and at 3°; GLOBE from 400 km over its centre
# looking 10° down (the sky marched per pixel, the limb). nc on the Earth as make_earth_nc finds
# it; GLOBE as make_earth builds it.
make_atmosphere() {
    local nc="$data/nc" globe="$data/globe" shots=() elevation sun shot
    trade_data
    if ! grep -q '^\[earth\]' "$nc/manifest.toml"; then
        nc="$data/nc_earth"
        [[ -f $nc/manifest.toml ]] || "$terramp_data" build --dem "$shared/nc/elev_ned_30m.tif" \
            --imagery "$shared/nc/landsat_multiband.tif" --bands 3,2,1 \
            --landcover "$shared/nc/landuse_r.tif" --classes nc --out "$nc" >/dev/null
    fi
    if ! grep -q '^\[earth\]' "$globe/manifest.toml" 2>/dev/null; then
        "$terramp_data" build --dem "$shared/globe/globe_g_30arcsec.tif" --out "$globe" >/dev/null
    fi
    local trees_at
    trees_at="impostors = \"$(cd "$impostors" && pwd)\""
    # Each exposed as a photographer would: EV100 15 by day, 12 at sunset, 8 at dusk.
    for shot in 40:15 1:12 -4:8; do
        elevation=${shot%:*}
        sun=$(layer "atmosphere_sun_$elevation" '[render]' 'sun_azimuth_deg = 270.0' "sun_elevation_deg = $elevation.0" \
            '[draw_seeds]' "$trees_at" '[display]' "ev100 = ${shot#*:}.0")
        "$terramp" render --dataset "$nc" --camera 637500,221750,300,270,0 --width 640 --height 360 \
            --settings "$sun" --out "$out/atmosphere_nc_$elevation.png" >/dev/null
        shots+=("$out/atmosphere_nc_$elevation.png")
    done
    sun=$(layer atmosphere_clear '[render]' 'sun_azimuth_deg = 270.0' 'sun_elevation_deg = 40.0' \
        '[atmosphere]' 'aerial_perspective = false' '[draw_seeds]' "$trees_at")
    "$terramp" render --dataset "$nc" --camera 637500,221750,300,270,0 --width 640 --height 360 \
        --settings "$sun" --out "$out/atmosphere_nc_clear.png" >/dev/null
    shots+=("$out/atmosphere_nc_clear.png")
    sun=$(layer atmosphere_high '[render]' 'sun_azimuth_deg = 270.0' 'sun_elevation_deg = 20.0')
    "$terramp" render --dataset "$nc" --camera 637500,221750,10000,270,-50 --width 640 --height 360 \
        --settings "$sun" --out "$out/atmosphere_nc_10km.png" >/dev/null
    shots+=("$out/atmosphere_nc_10km.png")
    for elevation in 40 3; do
        sun=$(layer "atmosphere_zion_$elevation" '[render]' 'sun_azimuth_deg = 250.0' "sun_elevation_deg = $elevation.0")
        "$terramp" render --dataset "$data/zion" --camera lonlat:-113.05,37.15,10000,0,-30 --width 640 \
            --height 360 --settings "$sun" --out "$out/atmosphere_zion_$elevation.png" >/dev/null
        shots+=("$out/atmosphere_zion_$elevation.png")
    done
    sun=$(layer atmosphere_orbit '[render]' 'sun_elevation_deg = 20.0')
    "$terramp" render --dataset "$globe" --camera lonlat:45,25,400000,0,-10 --width 640 --height 360 \
        --settings "$sun" --out "$out/atmosphere_globe_400km.png" >/dev/null
    shots+=("$out/atmosphere_globe_400km.png")
    compose --columns 2 --scale 0.75 --gap 4 --out docs/atmosphere_sky.png "${shots[@]}"
}

# The display's tone curves (docs/atmosphere.md): nc from 300 m looking west with the trade's
# trees, the sun in the west at 40°, at EV100 15 through AgX, ACES and the linear display.
make_display() {
    local shots=() curve settings trees_at
    trade_data
    trees_at="impostors = \"$(cd "$impostors" && pwd)\""
    for curve in agx aces linear; do
        settings=$(layer "display_$curve" '[render]' 'sun_azimuth_deg = 270.0' 'sun_elevation_deg = 40.0' \
            '[draw_seeds]' "$trees_at" '[display]' "tone_curve = \"$curve\"")
        "$terramp" render --dataset "$data/nc" --camera 637500,221750,300,270,0 --width 640 --height 360 \
            --settings "$settings" --out "$out/display_$curve.png" >/dev/null
        shots+=("$out/display_$curve.png")
    done
    compose --columns 3 --scale 0.5 --gap 4 --out docs/display_curves.png "${shots[@]}"
}

make_trees_health() {
    mkdir -p "$out/trees"
    local args=() health species
    for health in 1.0 0.5 0.1; do
        for species in spruce pine birch broadleaf bush; do
            "$terramp_data" tree --species "$species" --seed 7 --health "$health" \
                --out "$out/trees/$species-$health.glb" >/dev/null
            args+=(--model "$out/trees/$species-$health.glb")
        done
    done
    "$terramp_data" preview "${args[@]}" --columns 5 --cell 200,300 --out docs/trees_health.png >/dev/null
}

make_continuous_lod() {
    demo_data
    local trees=('[seeds]' 'class_table = "nc-generated"' '[draw_seeds]' "impostors = \"$root/data/impostors\"")
    views continuous data/default 4000,4500,350,50,-8 1280x720 "$(layer off "${trees[@]}" 'continuous_lod = false')" \
        "$(layer on "${trees[@]}" 'continuous_lod = true')"
    compose --crop 640,300,320,180 --scale 2 --filter nearest --gap 0 --out docs/continuous_lod_compare.png \
        "${shots[@]}"
}

make_truth_vs_accurate() {
    demo_data
    local pose=4000,4500,350,50,-8
    local trees=config/demo.toml
    "$terramp" truth --dataset data/default --camera "$pose" --preset accurate --impostors data/impostors \
        --settings "$trees" --out "$out/truth_ss4" >/dev/null
    local ss
    for ss in 1 2; do
        "$terramp" truth --dataset data/default --camera "$pose" --preset accurate --impostors data/impostors \
            --settings "$trees" --supersample "$ss" --out "$out/truth_ss$ss" >/dev/null
    done
    render --dataset data/default --camera "$pose" --preset accurate --settings "$trees" --out "$out/accurate.png"
    # Top: the truth (4 × 4) and the accurate frame; bottom: the FLIP maps against the truth of the
    # truth at one sample per pixel and of the accurate frame (their means are printed, and the
    # truth at 2 × 2 samples', for docs/truth.md).
    local ss1_map="$out/tva_flip_ss1.png" accurate_map="$out/tva_flip_accurate.png"
    compose --flip-reference "$out/truth_ss4/truth.png" --out "$ss1_map" "$out/truth_ss1/truth.png"
    compose --flip-reference "$out/truth_ss4/truth.png" --out "$out/tva_flip_ss2.png" "$out/truth_ss2/truth.png"
    compose --flip-reference "$out/truth_ss4/truth.png" --out "$accurate_map" "$out/accurate.png"
    compose --columns 2 --gap 6 --crop 320,250,640,330 --scale 0.75 --out docs/truth_vs_accurate.png \
        "$out/truth_ss4/truth.png" "$out/accurate.png" "$ss1_map" "$accurate_map"
}

make_viewer() {
    forest
    for tool in Xvfb xdotool xwd; do
        command -v "$tool" >/dev/null || { echo "viewer needs $tool: apt-get install xvfb xdotool x11-apps" >&2; return 1; }
    done
    local display=":$((90 + RANDOM % 9))"
    Xvfb "$display" -screen 0 1280x720x24 -nolisten tcp >/dev/null 2>&1 &
    local xvfb=$!
    sleep 2
    local view="$out/viewer.toml"
    layer viewer '[draw_seeds]' "impostors = \"$(cd "$forest" && pwd)\"" >/dev/null
    # A short flight down nc.toml's second leg, ending over the forest by the lakes.
    printf '[[key]]\nat = [%s]\nyaw_deg = %s\npitch_deg = %s\n\n' '635000.0, 220000.0, 700.0' 30.0 -15.0 '636560.0, 222060.0, 414.0' 41.0 -14.0 \
        >"$out/viewer_path.toml"
    DISPLAY="$display" "$terramp" view --dataset "$data/nc" --settings "$view" --path "$out/viewer_path.toml" \
        --path-frames 40 --width 1280 --height 720 --out "$out/view" 2>"$out/viewer.log" &
    local viewer=$!
    local waited=0
    until grep -q "path flown" "$out/viewer.log"; do
        sleep 2
        waited=$((waited + 2))
        if [[ $waited -gt 1800 ]] || ! kill -0 "$viewer" 2>/dev/null; then
            kill "$viewer" "$xvfb" 2>/dev/null || true
            echo "viewer: the path was never flown (see $out/viewer.log)" >&2
            return 1
        fi
    done
    sleep 10 # the last view's tiles and seeds settle; the overlay's graphs fill
    local id
    id=$(DISPLAY="$display" xdotool search --sync --name terramp | head -1)
    DISPLAY="$display" xwd -id "$id" -silent >"$out/viewer.xwd"
    kill "$viewer" "$xvfb" 2>/dev/null || true
    wait "$viewer" "$xvfb" 2>/dev/null || true
    compose --out docs/viewer_nc.png "$out/viewer.xwd"
}

make_wind() {
    pillow
    IMAGES_ONLY=1 OUT="$out/wind" DATA_DIR="$data" scripts/wind.sh
}

make_streaming() {
    IMAGES_ONLY=1 scripts/measure_streaming.sh "$out/streaming"
}

make_soak_globe() { pillow; FRAMES=10000 SOAKS=globe DATA_DIR="$data" scripts/soak.sh; }
make_soak_nc() { pillow; FRAMES=10000 SOAKS=nc DATA_DIR="$data" scripts/soak.sh; }
# The one-way flight and the flight there, back and there again of docs/RELIABILITY.md's soak section.
make_soak_nc_growth() { pillow; FRAMES=10000 LEGS=1 SOAKS=nc PLOT_NAME=nc_growth DATA_DIR="$data" scripts/soak.sh; }
make_soak_nc_there_and_back() {
    pillow
    FRAMES=900 LEGS=3 SOAKS=nc PLOT_NAME=nc_there_and_back DATA_DIR="$data" scripts/soak.sh
}
make_trade() { DATA_DIR="$data" scripts/trade.sh; }
make_trade_continuous_lod() { DATA_DIR="$data" scripts/continuous_lod.sh; }
make_trade_slicings() { DATA_DIR="$data" scripts/slicings_trade.sh; }
make_trade_texcells() { DATA_DIR="$data" scripts/texcells_truth.sh; }

for maker in "${wanted[@]}"; do
    started=$SECONDS
    echo "docs_images.sh: $maker ..." >&2
    "make_$maker"
    echo "docs_images.sh: $maker: $(rows | awk -v m="$maker" '$2 == m { printf "%s ", $1 }')($((SECONDS - started)) s)" >&2
done
