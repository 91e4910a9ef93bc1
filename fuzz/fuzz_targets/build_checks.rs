//! Whether the target was built with overflow checks and debug assertions, shown by the build
//! itself: run with `TERRAMP_FUZZ_PROBE=overflow`, a target multiplies `u32::MAX` by 2 (values
//! hidden from the optimiser) as it starts; with `TERRAMP_FUZZ_PROBE=debug_assertions`, it runs
//! `debug_assert!(false)`. Built with the checks, each panics (`attempt to multiply with
//! overflow`, `terramp-fuzz probe: debug assertions are on`) and the process aborts as on a
//! finding; built without them, the target says so and exits with status 3. `campaign.sh` runs
//! both probes on every target before fuzzing it. Without the variable, nothing happens.

use std::hint::black_box;

/// Runs the probe `TERRAMP_FUZZ_PROBE` names, if any; call first in the target's `init`.
pub fn probe() {
    let Some(what) = std::env::var_os("TERRAMP_FUZZ_PROBE") else { return };
    match what.to_str() {
        Some("overflow") => {
            let product = black_box(u32::MAX) * black_box(2);
            eprintln!("terramp-fuzz probe: overflow checks are OFF (u32::MAX * 2 gave {product})");
        }
        Some("debug_assertions") => {
            debug_assert!(black_box(false), "terramp-fuzz probe: debug assertions are on");
            eprintln!("terramp-fuzz probe: debug assertions are OFF");
        }
        _ => eprintln!("terramp-fuzz probe: TERRAMP_FUZZ_PROBE={what:?}: use overflow or debug_assertions"),
    }
    std::process::exit(3);
}
