#!/usr/bin/env bash
# Makes the frames the golden-image tests rendered the new references, after an intended change of
# the look. This is the only way a reference changes: no test run rewrites one, whatever its
# environment.
#
# It runs the golden tests (data-tools' render_nc and draw_seeds, which need ../shared/data): each
# writes its frame (and its control) to <target>/tmp/golden/ before comparing, so they may fail
# here on the very change being blessed. Every reference is then replaced by the frame rendered
# now, and the script prints how far each moved. Look at the new images before committing them.
set -euo pipefail
cd "$(dirname "$0")/.."
export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
# The references are lavapipe's frames (the golden tests compare only there), whatever the
# environment asks for.
export TERRAMP_ADAPTER=software
golden="${CARGO_TARGET_DIR:-target}/tmp/golden"
rm -rf "$golden"
cargo test -p terramp-data-tools --test render_nc --test draw_seeds --no-fail-fast -- --nocapture \
  | grep -E ' dB against the reference|test result' || true
for reference in data-tools/tests/reference/*.png; do
  fresh="$golden/$(basename "$reference")"
  if [[ ! -f "$fresh" ]]; then
    echo "bless: no frame for $reference in $golden: its test failed before rendering it" >&2
    exit 1
  fi
  cp "$fresh" "$reference"
  echo "bless: $reference <- $fresh"
done
