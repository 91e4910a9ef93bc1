#!/usr/bin/env bash
# The wind over nc/ (issue 14): the figures and images of docs/wind.md. One command:
#
#   scripts/wind.sh            # needs ../shared/data (nc/, zion/ and models/), as scripts/trade.sh
#
# 1. Popping: `terramp sweep` of `balanced` over nc/ with the shared models drawn, in still air and
#    in a wind of WIND m/s (default 12), each against its own ground truth (which sways with the same
#    wind, frame for frame), along the sweep's popping flight (POPPING_FRAMES, default 12, as the trade's: every
#    frame's largest 4 × 4 block change, and the truth's). Printed side by side: the issue asks
#    that the wind's popping stays within 20 % of still air's.
# 2. The strip: STRIP_FRAMES (8) frames of one pose low over forest by a pond (STRIP_AT, STRIP_YAW,
#    STRIP_PITCH) (`terramp fly` on a one-key
#    path), WIND m/s at STRIP_HZ (4) wind frames per second, each cropped to the trees
#    ($OUT/strip/crop_N.png), and every other one side by side (docs/wind_strip.png: 0.5 s apart).
#
# Environment: WIND, POPPING_FRAMES, STRIP_FRAMES, STRIP_HZ, DATA_DIR (data/trade), OUT (a scratch
# folder, default /tmp/terramp-wind), IMAGES_ONLY (1: the strip alone, as scripts/docs_images.sh
# makes it).
set -euo pipefail

source "$(dirname "${BASH_SOURCE[0]}")/measure_env.sh" nc zion models
wind="${WIND:-12}"
data="${DATA_DIR:-data/trade}"
out="${OUT:-/tmp/terramp-wind}"
mkdir -p "$data" "$out"
cargo build --release --workspace -q
source scripts/trade_data.sh

still="$out/still.toml"
windy="$out/windy.toml"
cp "$trees" "$still"
{ cat "$trees"; printf '[wind]\nspeed_m_s = %s\n' "$wind"; } >"$windy"

# 1. Popping, still and windy, each against its own truth.
[[ "${IMAGES_ONLY:-0}" == 1 ]] && names=() || names=(still windy)
for name in "${names[@]}"; do
    echo "## popping, $name" >&2
    "$terramp" sweep --dataset "$data/nc" --out "$out/sweep_$name" --presets balanced --frames 4 --warmup 2 \
        --timing-rounds 1 --samples 1 --popping-frames "${POPPING_FRAMES:-12}" --settings "$out/$name.toml"
done
[[ "${IMAGES_ONLY:-0}" == 1 ]] || python3 - "$out" "$wind" <<'PY'
import json, sys
out, wind = sys.argv[1], sys.argv[2]
def popping(name):
    point = json.load(open(f"{out}/sweep_{name}/trade.json"))["points"][0]
    return point["popping"]
still, windy = popping("still"), popping("windy")
print(f"popping along nc/'s flight, balanced ({still['pairs']} frame pairs): largest 4x4 block change, "
      f"the truth's, and the difference")
for name, p in (("still air", still), (f"wind {wind} m/s", windy)):
    print(f"  {name:>12}: {p['largest']:.1f}  truth {p['truth_largest']:.1f}  popping {p['popping']:+.1f}")
print(f"  wind / still: popping {windy['popping'] / still['popping']:.2f}x, "
      f"largest change {windy['largest'] / still['largest']:.2f}x")
PY

# 2. The strip: one pose, the trees swaying.
frames="${STRIP_FRAMES:-8}"
settle=24
printf '[[key]]\nat = [%s]\nyaw_deg = %s\npitch_deg = %s\n' "${STRIP_AT:-634000, 222000, 175}" \
    "${STRIP_YAW:-45}" "${STRIP_PITCH:--8}" >"$out/strip_path.toml"
{ cat "$windy"; printf 'frame_rate_hz = %s\n' "${STRIP_HZ:-4}"; } >"$out/strip.toml"
rm -rf "$out/strip"
"$terramp" fly --dataset "$data/nc" --path "$out/strip_path.toml" --frames $((settle + frames)) \
    --width 960 --height 540 --out "$out/strip" --settings "$out/strip.toml"
python3 - "$out/strip" "$settle" "$frames" "${STRIP_HZ:-4}" "$wind" <<'PY'
import sys
from PIL import Image
folder, settle, frames, hz, wind = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
box = (240, 240, 720, 540)  # the nearest trees, 480 x 300
crops = []
for k in range(frames):
    image = Image.open(f"{folder}/frame_{settle + k:04d}.png").convert("RGB").crop(box)
    image.save(f"{folder}/crop_{k}.png")
    crops.append(image)
shown = crops[::2]
w, h = shown[0].size
strip = Image.new("RGB", (w * len(shown), h))
for k, image in enumerate(shown):
    strip.paste(image, (k * w, 0))
strip.save("docs/wind_strip.png")
print(f"docs/wind_strip.png: {len(shown)} frames {2 / hz:.2f} s apart, wind {wind} m/s")
PY
