#!/usr/bin/env bash
# Runs every fuzz target (or those named after RUNS) for RUNS executions each, one after the
# other, over its corpus (fuzz/seed_corpora.sh), and prints a table: target, executions, seconds,
# executions per second, corpus entries, crashes saved. Logs go to fuzz/logs/<target>.log.
# Needs the targets built: cargo +stable fuzz build --sanitizer none -O
set -euo pipefail
cd "$(dirname "$0")"
runs="${1:?usage: campaign.sh RUNS [TARGET...]}"
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(settings_toml camera_path_toml class_table_toml pack dataset_manifest gltf_model impostor)
bin=target/x86_64-unknown-linux-gnu/release
mkdir -p logs
printf '%-18s %12s %8s %8s %8s %8s\n' target executions seconds exec/s corpus crashes
for t in "${targets[@]}"; do
  mkdir -p "corpus/$t" "artifacts/$t"
  # Text inputs up to 16 KiB (each table of the defaults fits); models up to 32 KiB (the larger
  # seeds, cut there, decode megapixel textures at every input: 88 inputs/s); other binary inputs
  # up to 256 KiB (the packs seeded are larger than libFuzzer's default). libFuzzer's default
  # one-second-per-input limit is raised for the slowest inputs.
  case "$t" in
    *_toml | dataset_manifest) max_len=16384 ;;
    gltf_model) max_len=32768 ;;
    *) max_len=262144 ;;
  esac
  set +e
  "$bin/$t" "corpus/$t" -runs="$runs" -max_len="$max_len" -timeout=20 -rss_limit_mb=2048 \
    -artifact_prefix="artifacts/$t/" -print_final_stats=1 >"logs/$t.log" 2>&1
  status=$?
  set -e
  executed=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "logs/$t.log" | grep -o '[0-9]*$' || echo 0)
  seconds=$(grep -o 'Done [0-9]* runs in [0-9]*' "logs/$t.log" | grep -o '[0-9]*$' || echo '?')
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "logs/$t.log" | grep -o '[0-9]*$' || echo 0)
  printf '%-18s %12s %8s %8s %8s %8s%s\n' "$t" "$executed" "$seconds" "$rate" "$(ls "corpus/$t" | wc -l)" \
    "$(ls "artifacts/$t" | wc -l)" "$([ $status -eq 0 ] || echo "  (exit $status: see logs/$t.log)")"
done
