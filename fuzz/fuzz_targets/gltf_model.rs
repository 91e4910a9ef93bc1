//! A model given to the baker (`.glb` or `.gltf` bytes): read into a mesh, or refused with a
//! `ModelError`; never a panic or an unbounded allocation.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod build_checks;

fuzz_target!(init: build_checks::probe(), |bytes: &[u8]| {
    let path = std::env::temp_dir().join(format!("terramp-fuzz-model-{}.glb", std::process::id()));
    if std::fs::write(&path, bytes).is_ok() {
        let _ = terramp::bake::load_model(&path);
    }
});
