//! A settings layer (`--settings FILE`, presets) of any text: loads or is refused with a
//! `SettingsError` naming the key; never panics.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod build_checks;

fuzz_target!(init: build_checks::probe(), |text: &str| {
    let _ = terramp::config::Settings::from_layers(&[("fuzz.toml".to_owned(), text.to_owned())]);
});
