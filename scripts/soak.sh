#!/usr/bin/env bash
# The soak (issue 18): long flights with everything drawn, memory logged every frame, and its
# growth after the warm-up judged and plotted. Not a test: it takes a while (`tests/
# seed_flight_memory.rs` is the short guard CI runs).
#
#   scripts/soak.sh                 # nc with the trade's trees, then globe; 10,000 frames each
#   FRAMES=2000 SOAKS=nc scripts/soak.sh
#
# Each flight is `terramp fly --save-every 0` along the dataset's path, with wind and cloud shadows
# on (they change uniforms every frame), into out/soak/<name>/log.jsonl; `scripts/soak_plot.py`
# then prints the anonymous and total resident memory every 100 frames, the rise of the floor after
# the warm-up (bound: 16 MiB), and draws docs/soak_<name>.png.
#
# The path is flown LEGS times, there and back, and the first leg is the warm-up: memory rises with
# the heaviest frame drawn so far, until the flight has shown its heaviest view (a one-way nc
# flight rose 357 MiB over 5,000 frames that way, and flying the same views twice more added
# 2.6 MiB: docs/RELIABILITY.md).
#
# Environment: FRAMES (10000), LEGS (5), WIDTH × HEIGHT (320 × 180), SOAKS ("nc globe"), PLOT_NAME
# (the plot is docs/soak_<PLOT_NAME>.png; default: the soak's name), DATA_DIR
# (data/trade: nc/ and the trade's impostors, as scripts/trade.sh builds them; globe/ is built there
# from ../shared/data/globe when missing).
set -euo pipefail
cd "$(dirname "$0")/.."

FRAMES=${FRAMES:-10000}
WIDTH=${WIDTH:-320}
HEIGHT=${HEIGHT:-180}
SOAKS=${SOAKS:-nc globe}
LEGS=${LEGS:-5}
DATA_DIR=${DATA_DIR:-data/trade}
export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}

cargo build --release --bin terramp
cargo build --release -p terramp-data-tools --bin terramp-data
bin=target/release
weather=out/soak/weather.toml
mkdir -p out/soak
cat > "$weather" <<TOML
# Written by scripts/soak.sh: the trees, swaying, under drifting cloud shadows.
[draw_seeds]
impostors = "$(realpath "$DATA_DIR/impostors")"
[wind]
speed_m_s = 9.0
[clouds]
coverage = 0.4
TOML

for name in $SOAKS; do
  case $name in
    nc) dataset=$DATA_DIR/nc; path=config/paths/nc.toml ;;
    globe)
      dataset=$DATA_DIR/globe; path=config/paths/globe.toml
      [ -f "$dataset/manifest.toml" ] || "$bin/terramp-data" build --dem ../shared/data/globe/globe_g_30arcsec.tif --out "$dataset" ;;
    *) echo "unknown soak $name (nc, globe)"; exit 1 ;;
  esac
  echo "soak: $name, $FRAMES frames at ${WIDTH}×${HEIGHT}, the path flown $LEGS times (there and back)"
  mkdir -p "out/soak/$name"
  # The path there, back, there...: LEGS legs, each turning at the other end (the key there once).
  python3 - "$path" "$LEGS" > "out/soak/$name/path.toml" <<'PY'
import sys, tomllib
keys = tomllib.load(open(sys.argv[1], "rb"))["key"]
n = len(keys)
order = list(range(n))
for leg in range(1, int(sys.argv[2])):
    order += list(range(n - 2, -1, -1)) if leg % 2 else list(range(1, n))
print(f"# {sys.argv[1]} flown {sys.argv[2]} times, there and back (scripts/soak.sh).")
for k in order:
    print("\n[[key]]")
    for name, value in keys[k].items():
        print(f"{name} = {value}")
PY
  path="out/soak/$name/path.toml"
  /usr/bin/time -v "$bin/terramp" fly --dataset "$dataset" --path "$path" --frames "$FRAMES" --save-every 0 \
    --width "$WIDTH" --height "$HEIGHT" --settings "$weather" --out "out/soak/$name" 2> "out/soak/$name/time.txt" \
    || { tail -5 "out/soak/$name/time.txt"; exit 1; }
  WARM_UP=$((FRAMES / LEGS)) python3 scripts/soak_plot.py "docs/soak_${PLOT_NAME:-$name}.png" "out/soak/$name/log.jsonl" || failed=1
done
exit "${failed:-0}"
