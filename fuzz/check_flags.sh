#!/usr/bin/env bash
# Which cargo-fuzz flags give overflow checks and debug assertions: builds a target that is only
# fuzz_targets/build_checks.rs's probe (no terramp, so it builds in a minute or two) in a
# temporary project, four ways (-O with a release profile that sets neither, -O -a, neither flag,
# -O with this crate's profile), and prints what its two probes say for each. README.md quotes it.
set -euo pipefail
cd "$(dirname "$0")"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/src" "$tmp/fuzz/fuzz_targets"
printf '[package]\nname = "flag-check"\nversion = "0.0.0"\nedition = "2024"\n\n[workspace]\nexclude = ["fuzz"]\n' \
  >"$tmp/Cargo.toml"
: >"$tmp/src/lib.rs"
cp fuzz_targets/build_checks.rs "$tmp/fuzz/fuzz_targets/"
cat >"$tmp/fuzz/fuzz_targets/probe.rs" <<'EOF'
#![no_main]
mod build_checks;
libfuzzer_sys::fuzz_target!(init: build_checks::probe(), |_bytes: &[u8]| {});
EOF
manifest() {
  printf '[package]\nname = "flag-check-fuzz"\nversion = "0.0.0"\nedition = "2024"\n\n'
  printf '[package.metadata]\ncargo-fuzz = true\n\n[dependencies]\nlibfuzzer-sys = "0.4"\n\n'
  printf '[[bin]]\nname = "probe"\npath = "fuzz_targets/probe.rs"\ntest = false\ndoc = false\n\n'
  printf '[workspace]\nmembers = ["."]\n\n[profile.release]\ndebug = "line-tables-only"\n%s' "$1"
}
cp Cargo.lock "$tmp/fuzz/"
cd "$tmp/fuzz"
for way in "-O:" "-O -a:" ":" "-O:debug-assertions = true
overflow-checks = true"; do
  flags=${way%%:*}
  manifest "${way#*:}" >Cargo.toml
  cargo +stable fuzz build --sanitizer none $flags probe >/dev/null 2>&1
  result=""
  for probe in overflow debug_assertions; do
    out=$(TERRAMP_FUZZ_PROBE=$probe target/x86_64-unknown-linux-gnu/release/probe -runs=0 2>&1 || true)
    result+="$(grep -o 'attempt to multiply with overflow\|debug assertions are on\|overflow checks are OFF\|debug assertions are OFF' <<<"$out" | head -1); "
  done
  profile=$([ -n "${way#*:}" ] && echo "with the profile's checks" || echo "profile sets neither")
  printf '%-8s %-26s %s\n' "${flags:-(none)}" "$profile" "$result"
done
cargo +stable fuzz --version
