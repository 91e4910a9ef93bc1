//! Synthetic datasets, built once per test process and shared by its tests. They are never reused
//! across runs, so a change to the generator is always what is tested.

use std::path::PathBuf;
use std::sync::Mutex;

use terramp::synth::SynthParams;

use crate::data::target_tmp_dir;

/// The synthetic datasets this test process built, by parameters.
static BUILT: Mutex<Vec<(String, PathBuf)>> = Mutex::new(Vec::new());

/// A synthetic dataset of `size`² samples.
pub fn synth_dataset(size: u32, seed: u64) -> PathBuf {
    synth_dataset_with(&SynthParams { size, seed, ..Default::default() })
}

/// As `synth_dataset`, for any parameters (spacing, origin, water level).
pub fn synth_dataset_with(params: &SynthParams) -> PathBuf {
    let key = format!("{params:?}");
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, dir)) = built.iter().find(|(k, _)| *k == key) {
        return dir.clone();
    }
    let root = target_tmp_dir();
    if built.is_empty() {
        // Earlier runs' datasets: cargo runs test binaries one after another, so none is in use.
        for entry in std::fs::read_dir(&root).into_iter().flatten().flatten() {
            if entry.file_name().to_string_lossy().starts_with("synth-") {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
    let (size, seed, n) = (params.size, params.seed, built.len());
    let dir = root.join(format!("synth-{size}-{seed}-{n}-{}", std::process::id()));
    terramp::synth::synthesize(&dir, params, false).unwrap();
    built.push((key, dir.clone()));
    dir
}
