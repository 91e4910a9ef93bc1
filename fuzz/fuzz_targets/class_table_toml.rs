//! A land-cover class table (`--classes FILE`) of any text: parses, or is refused with a
//! `ClassTableError` naming table, class and key; never panics.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod build_checks;

fuzz_target!(init: build_checks::probe(), |text: &str| {
    let _ = terramp::classes::ClassTable::parse(text, "fuzz.toml");
});
