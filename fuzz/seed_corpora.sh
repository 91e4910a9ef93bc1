#!/usr/bin/env bash
# Seeds each fuzz target's corpus (fuzz/corpus/<target>/, not committed) from real files: the
# settings, presets, camera paths and class tables in config/, the manifests and packs of a small
# synthetic dataset and of the datasets under data/ (when built), and the glTF models in
# ../shared/data/models, and the impostor target's template. Needs the release `terramp-data`
# (cargo build --release -p terramp-data-tools) and, for the impostor seeds, the targets built.
set -euo pipefail
cd "$(dirname "$0")"
root=..
terramp_data="${CARGO_TARGET_DIR:-$root/target}/release/terramp-data"
shared="${SHARED:-$root/../shared/data}"
corpus=corpus
mkdir -p "$corpus"/{settings_toml,camera_path_toml,class_table_toml,pack,dataset_manifest,gltf_model,impostor}
cp "$root"/config/default.toml "$root"/config/presets/*.toml "$corpus/settings_toml/"
# Each table of the defaults on its own too: small inputs that reach every key.
awk -v out="$corpus/settings_toml/default-" '/^\[/ { n++ } n { print > (out n ".toml") }' "$root"/config/default.toml
cp "$root"/config/paths/*.toml "$corpus/camera_path_toml/"
cp "$root"/config/classes/*.toml "$corpus/class_table_toml/"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$terramp_data" synth --size 40 --out "$tmp/tiny" >/dev/null
"$terramp_data" synth --size 40 --imagery-format bc1 --out "$tmp/tiny-bc1" >/dev/null
for d in "$tmp/tiny" "$tmp/tiny-bc1" "$root"/data/*/ "$root"/data/trade/*/; do
  [ -f "$d/manifest.toml" ] || continue
  name=$(basename "$d")
  cp "$d/manifest.toml" "$corpus/dataset_manifest/$name.toml"
  for p in "$d"/*.pack; do
    # Packs up to 1 MiB: libFuzzer's inputs are kept small. The pack target's inputs lead with a
    # byte saying which checksums it makes match (7: all).
    [ "$(stat -c %s "$p")" -le 1048576 ] && { printf '\007'; cat "$p"; } >"$corpus/pack/$name-$(basename "$p")"
  done
done
if [ -d "$shared/models" ]; then
  cp "$shared"/models/*.glb "$corpus/gltf_model/"
  # The impostor target's template: a real model (with a slicing) baked small; the target adds a
  # small forest sample and writes one seed per file of the whole (its index first, as it picks
  # files), so it must be built first.
  rm -rf impostor_template
  "$terramp_data" bake --model "$shared/models/Bush_1.glb" --texels 64 --slicings 2x2 \
    --out impostor_template >/dev/null
  impostor=target/x86_64-unknown-linux-gnu/release/impostor
  if [ -x "$impostor" ]; then
    TERRAMP_FUZZ_SEEDS="$corpus/impostor" "$impostor" -runs=0 >/dev/null 2>&1
  else
    echo "seed_corpora: $impostor is not built (cargo +stable fuzz build --sanitizer none -O -a): its corpus starts empty" >&2
  fi
else
  echo "seed_corpora: $shared/models is missing: the glTF and impostor corpora start empty" >&2
fi
for t in "$corpus"/*; do echo "$(basename "$t"): $(ls "$t" | wc -l) seeds"; done
