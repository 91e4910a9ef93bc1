#!/usr/bin/env bash
# Runs every fuzz target (or those named after RUNS) for RUNS executions each, one after the
# other, over its corpus (fuzz/seed_corpora.sh), and prints a table: target, executions, seconds,
# executions per second, peak resident memory, corpus entries, crashes saved. Logs go to
# fuzz/logs/<target>.log. Needs the targets built with optimisations, overflow checks and debug
# assertions:
#   cargo +stable fuzz build --sanitizer none -O -a
# (`-O` alone turns cargo-fuzz's `-Cdebug-assertions` off, and the overflow checks with it; this
# crate's release profile turns both back on). Before fuzzing a target, its binary is probed
# (fuzz_targets/build_checks.rs): an overflowing multiply and a `debug_assert!(false)` must each
# abort it. A binary built without them is refused, and nothing is run.
set -euo pipefail
cd "$(dirname "$0")"
runs="${1:?usage: campaign.sh RUNS [TARGET...]}"
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(settings_toml camera_path_toml class_table_toml pack dataset_manifest gltf_model impostor)
bin=target/x86_64-unknown-linux-gnu/release
mkdir -p logs
probe_dir=$(mktemp -d)
trap 'rm -rf "$probe_dir"' EXIT

# Whether the binary of target $1 aborts on probe $2 with message $3.
aborts_on() {
  local out
  out=$(TERRAMP_FUZZ_PROBE="$2" "$bin/$1" -runs=0 -artifact_prefix="$probe_dir/" 2>&1 || true)
  grep -qF "$3" <<<"$out"
}
for t in "${targets[@]}"; do
  [ -x "$bin/$t" ] || { echo "campaign: $bin/$t is not built (cargo +stable fuzz build --sanitizer none -O -a)" >&2; exit 1; }
  if ! aborts_on "$t" overflow 'attempt to multiply with overflow' ||
    ! aborts_on "$t" debug_assertions 'terramp-fuzz probe: debug assertions are on'; then
    echo "campaign: $bin/$t was built without overflow checks or debug assertions; build it with" >&2
    echo "  cargo +stable fuzz build --sanitizer none -O -a" >&2
    exit 1
  fi
done
echo "every target's binary aborts on an overflowing multiply and on a failed debug assertion"

# libFuzzer's final statistic $2 from log $1.
final_stat() { grep -o "stat::$2: *[0-9]*" "$1" | grep -o '[0-9]*$' || echo '?'; }
printf '%-18s %12s %8s %8s %8s %8s %8s\n' target executions seconds exec/s rss_mb corpus crashes
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
  start=$(date +%s)
  set +e
  "$bin/$t" "corpus/$t" -runs="$runs" -max_len="$max_len" -timeout=20 -rss_limit_mb=2048 \
    -artifact_prefix="artifacts/$t/" -print_final_stats=1 >"logs/$t.log" 2>&1
  status=$?
  set -e
  wall=$(($(date +%s) - start))
  # libFuzzer's own count of the time on a clean finish; the wall clock after a crash.
  seconds=$(grep -o 'Done [0-9]* runs in [0-9]*' "logs/$t.log" | grep -o '[0-9]*$' || echo "$wall")
  printf '%-18s %12s %8s %8s %8s %8s %8s%s\n' "$t" "$(final_stat "logs/$t.log" number_of_executed_units)" "$seconds" \
    "$(final_stat "logs/$t.log" average_exec_per_sec)" "$(final_stat "logs/$t.log" peak_rss_mb)" "$(ls "corpus/$t" | wc -l)" \
    "$(ls "artifacts/$t" | wc -l)" "$([ $status -eq 0 ] || echo "  (exit $status: see logs/$t.log)")"
done
