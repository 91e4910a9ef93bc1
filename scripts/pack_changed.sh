#!/usr/bin/env bash
# A dataset's packs cut short under a running `terramp fly` (issue 42, item 8): copies DATASET,
# starts `terramp fly` over the copy along PATH, truncates its height, imagery and land-cover packs
# to half their length DELAY seconds in, and prints the flight's exit status and how many tiles it
# reported changed on disk. Before packs were read with positioned reads this was a SIGBUS ("Bus
# error", status 135); `tests/pack_changed.rs` is the test CI runs.
#
#   scripts/pack_changed.sh data/nc config/paths/nc.toml
#
# Environment: TERRAMP (the binary, default target/release/terramp), DELAY (1.2 s), FRAMES (40),
# WIDTH × HEIGHT (320 × 180), WORK (a scratch folder, default a new one under /tmp).
set -euo pipefail
dataset=${1:?usage: scripts/pack_changed.sh DATASET PATH.toml}
path=${2:?usage: scripts/pack_changed.sh DATASET PATH.toml}
terramp=${TERRAMP:-target/release/terramp}
work=${WORK:-$(mktemp -d /tmp/terramp-pack-changed.XXXXXX)}
copy="$work/dataset"
rm -rf "$copy" "$work/out"
cp -r "$dataset" "$copy"
"$terramp" fly --dataset "$copy" --path "$path" --frames "${FRAMES:-40}" --save-every 0 \
    --width "${WIDTH:-320}" --height "${HEIGHT:-180}" --out "$work/out" \
    >"$work/stdout" 2>"$work/stderr" &
flight=$!
sleep "${DELAY:-1.2}"
for pack in height imagery landcover; do
    file="$copy/$pack.pack"
    truncate -s $(($(stat -c %s "$file") / 2)) "$file"
done
status=0
wait "$flight" || status=$?
changed=$(grep -c 'changed on disk since it was opened' "$work/stderr" || true)
echo "exit status $status; $changed tiles reported changed on disk; stderr in $work/stderr"
