#!/usr/bin/env bash
# Seed selection figures (issue: seeds): pass 3's rate on the software adapter (or whatever
# adapter wgpu finds) for ~100 k, 1 M and 4 M checked seeds with its CPU twin's rate on the same
# input, then recall and precision against the exact oracle for every preset on nc/ and zion/
# at 1280×720, then the seed spacing across cell borders per preset (docs/seeds.md). Needs
# ../shared/data. Usage: scripts/measure_seeds.sh
set -euo pipefail
cd "$(dirname "$0")/.."
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
echo "## pass 3 rate (cargo bench --bench seeds)"
cargo bench -q --bench seeds 2>/dev/null | grep -v '^$'
echo
echo "## recall and precision against the oracle"
echo "| dataset | view | preset | visible (oracle) | recall | precision |"
echo "|---|---|---|---|---|---|"
cargo test -q --release -p terramp-data-tools --test seeds -- --ignored --nocapture recall_and_precision_per_preset 2>/dev/null |
    grep '^| '
echo
echo "## seed spacing across cell borders"
cargo test -q -p terramp-data-tools --test seed_spacing -- --nocapture 2>/dev/null | grep '^| '
