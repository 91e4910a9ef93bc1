#!/usr/bin/env bash
# Bruneton's reference sky for tests/bruneton.rs (docs/atmosphere.md): builds the CPU reference
# model of ebruneton/precomputed_atmospheric_scattering (atmosphere/reference, BSD licence) with
# scripts/bruneton/sky.cc, which sets his model_test.cc atmosphere at 440, 560 and 680 nm (his
# spectra are reduced from 47 wavelengths to these 3, sampled at 440, 560 and 680 nm, so the CPU
# precomputation takes about 20 minutes on 2 cores, not hours), precomputes his tables with ORDERS
# orders of scattering (4 is his default; 1 is single scattering alone, seconds), and prints the
# sky's radiance per unit of solar irradiance for the views tests/bruneton.rs lists:
#   altitude_m sun_deg view_elevation_deg view_azimuth_deg radiance_680 radiance_560 radiance_440
#
# Usage: scripts/bruneton_reference.sh ORDERS [WORK_DIR] > sky.txt
#   (tests/bruneton_sky.txt is ORDERS 4, tests/bruneton_single.txt ORDERS 1, each under a header)
# It clones the three repositories at the commits below into WORK_DIR (default
# /tmp/bruneton-reference) unless they are there; needs git, g++ and the network once.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
orders="${1:?usage: scripts/bruneton_reference.sh ORDERS [WORK_DIR]}"
work="${2:-/tmp/bruneton-reference}"
model=d9954923ccd810be2d4443268a182bcb96544c1e
types=1bf62b699f91d380ae9cfe6516891a89af77186d
progress=b34cdce09e505e36df90bd7e3b621949f5a52c24
fetch() {  # fetch URL DIR COMMIT
    if [[ ! -d $2/.git ]]; then
        git clone --quiet "$1" "$2"
    fi
    git -C "$2" checkout --quiet "$3"
}
mkdir -p "$work"
fetch https://github.com/ebruneton/precomputed_atmospheric_scattering "$work/model" "$model"
fetch https://github.com/ebruneton/dimensional_types "$work/model/external/dimensional_types" "$types"
fetch https://github.com/ebruneton/progress_bar "$work/model/external/progress_bar" "$progress"
cd "$work/model"
# Three wavelengths instead of 47 from 360 to 830 nm: a function of N samples over [MIN, MAX]
# samples MIN + (MAX - MIN) i / N, so 3 over [440, 800] are 440, 560 and 680 nm.
sed -i 's/U1, U2, U3, U4, U5, 47, 360, 830>;/U1, U2, U3, U4, U5, 3, 440, 800>;/' atmosphere/reference/definitions.h
grep -q 'U5, 3, 440, 800>;' atmosphere/reference/definitions.h
g++ -O2 -std=c++11 -I. -Iexternal/dimensional_types -Iexternal/progress_bar -pthread "$here/bruneton/sky.cc" \
    atmosphere/reference/model.cc atmosphere/reference/functions.cc external/progress_bar/util/progress_bar.cc \
    -o "$work/sky"
mkdir -p "$work/cache_$orders"
# His progress bar goes to stdout: keep only the result lines.
"$work/sky" "$orders" "$work/cache_$orders/" | tr '\r' '\n' | grep -E '^[0-9]'
