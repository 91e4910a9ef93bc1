//! A dataset folder whose `manifest.toml` is any text, beside the packs of a small synthetic
//! dataset: opened and a tile of every layer read, or refused with a `DatasetError` naming the
//! manifest; never a panic.
#![no_main]
use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

mod build_checks;
use terramp::dataset::{Dataset, TileId};

/// A 64-sample synthetic dataset, made once per process.
fn dataset() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("terramp-fuzz-dataset-{}", std::process::id()));
        let params = terramp::synth::SynthParams { size: 64, ..Default::default() };
        terramp::synth::synthesize(&dir, &params, false).expect("a synthetic dataset");
        dir
    })
}

fuzz_target!(init: build_checks::probe(), |text: &str| {
    let dir = dataset();
    if std::fs::write(dir.join("manifest.toml"), text).is_err() {
        return;
    }
    if let Ok(dataset) = Dataset::open(dir) {
        let root = TileId::new(0, 0, 0);
        let _ = dataset.height.tile_bytes(root);
        for layer in [&dataset.imagery, &dataset.landcover, &dataset.valid_mask].into_iter().flatten() {
            let _ = layer.tile_texels(root);
        }
        let _ = dataset.height_at(10.0, 10.0, 0);
    }
});
