//! The shared models of the nc class table (which the synthetic land cover uses too), baked into
//! impostors once per test run into the target's scratch folder, for tests that draw seeds.
//! Baking skips models already baked in the current format, and writes each model's folder
//! atomically, so test binaries may share the folder.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use terramp::bake::{BakeOptions, SlicingOptions, bake_missing};
use terramp::classes::ClassTable;

use crate::data::{shared_data, target_tmp_dir};

/// The baked folder, or `None` when the shared data is skipped (`TERRAMP_SKIP_SHARED=1`).
pub fn nc_impostors() -> Option<&'static Path> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    // Small atlases: enough for test views, quick to bake.
    DIR.get_or_init(|| bake_nc("nc-impostors", BakeOptions { texels: 256, ..Default::default() })).as_deref()
}

/// The same models baked with slicings too (6 × 5, `BakeOptions::slicing`), into a folder of
/// their own.
pub fn nc_sliced_impostors() -> Option<&'static Path> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    let options = BakeOptions {
        texels: 512,
        slicing: Some(SlicingOptions { orientations: 6, slices: 5 }),
        ..Default::default()
    };
    DIR.get_or_init(|| bake_nc("nc-impostors-sliced", options)).as_deref()
}

fn bake_nc(folder: &str, options: BakeOptions) -> Option<PathBuf> {
    let models = shared_data()?.join("models");
    let table = ClassTable::load("nc").unwrap();
    let names: Vec<&str> = table.species.iter().map(|s| s.model.as_str()).collect();
    let out = target_tmp_dir().join(folder);
    let missing = bake_missing(Some(&crate::gpu()), &models, &names, &out, &options, false).unwrap();
    assert!(missing.absent.is_empty(), "models missing: {:?}", missing.absent);
    Some(out)
}

/// nc's class table with `line` (e.g. `ground_blend = 0.0`) added to every species, written once
/// per process to the target's temporary folder under `name`: a table that differs from nc's by
/// one key of every species.
pub fn nc_table_with(name: &str, line: &str) -> std::path::PathBuf {
    let nc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../config/classes/nc.toml"))
        .expect("config/classes/nc.toml");
    let species = nc.matches("max_slope_deg = ").count();
    assert!(species >= 4, "nc's table has {species} species");
    let text = nc.lines().fold(String::new(), |mut out, l| {
        out.push_str(l);
        out.push('\n');
        if l.starts_with("max_slope_deg = ") {
            out.push_str(line);
            out.push('\n');
        }
        out
    });
    let path = std::env::temp_dir().join(format!("terramp-{name}-{}.toml", std::process::id()));
    std::fs::write(&path, text).expect("writing a class table");
    path
}
