//! A baked impostor folder (`impostor.toml`, its atlas PNGs, `mesh.bin`) and a forest sample
//! (`texcells/<code>/texcell.toml`, `texels.bin`) with one file replaced by any bytes: loaded, or
//! refused with an `ImpostorError` / `TexcellError` naming the file; never a panic.
//!
//! The input's first byte picks the file (the template's files sorted by relative path, modulo
//! their count), the rest is its content. The template is a real model baked small by
//! `seed_corpora.sh` into `impostor_template/`, beside which the target saves a forest sample of
//! 4 slices of 8 texels through the real writer (a baked one is megabytes, read and checksummed
//! at every input). It is made once per process in a temporary folder, and the changed file put
//! back after every input, so each input sees the template with exactly one file changed.
//!
//! Seeds: run with `TERRAMP_FUZZ_SEEDS=DIR`, the target writes one seed per template file into
//! DIR (its index, then its bytes) and exits (`seed_corpora.sh` does).
#![no_main]
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

mod build_checks;
use terramp::texcell::pyramid::Layer;
use terramp::texcell::{ForestSample, SampleTree};

struct Template {
    /// The folder the inputs change.
    dir: PathBuf,
    /// Every file under it, relative path (sorted) and original bytes.
    files: Vec<(PathBuf, Vec<u8>)>,
    /// Its impostors (folders holding `impostor.toml`).
    models: Vec<String>,
}

/// The forest sample's class code.
const CLASS: u8 = 5;

/// 4 slices of 8 texels with a few trees' worth of coverage, through the real pyramid.
fn small_sample() -> ForestSample {
    let finest: Vec<Layer> = (0..4)
        .map(|k| Layer {
            side: 8,
            texels: (0..64)
                .map(|i| if (i + k) % 5 == 0 { [0.1, 0.3, 0.05, 0.6] } else { [0.0; 4] })
                .collect(),
        })
        .collect();
    let (slices, volume) = terramp::texcell::sample_images(finest);
    let tree = SampleTree { model: "Pine_1".into(), position_m: [3.0, 4.0], height_m: 12.5, angle_deg: 30.0 };
    ForestSample {
        class_code: CLASS,
        class_name: "forest".into(),
        cell_m: 32.0,
        height_m: 13.0,
        trees: vec![tree],
        slices,
        volume,
    }
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("the copy's folder");
    for entry in std::fs::read_dir(from).expect("the template folder") {
        let path = entry.expect("a template entry").path();
        let name = path.file_name().expect("a name");
        if path.is_dir() {
            copy_tree(&path, &to.join(name));
        } else {
            std::fs::copy(&path, to.join(name)).expect("a copied file");
        }
    }
}

fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("the template's copy") {
        let path = entry.expect("an entry").path();
        if path.is_dir() {
            walk(root, &path, out);
        } else {
            out.push(path.strip_prefix(root).expect("under the root").to_owned());
        }
    }
}

fn template() -> &'static Template {
    static TEMPLATE: OnceLock<Template> = OnceLock::new();
    TEMPLATE.get_or_init(|| {
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("impostor_template");
        assert!(source.is_dir(), "{} is missing: run fuzz/seed_corpora.sh first", source.display());
        let dir = std::env::temp_dir().join(format!("terramp-fuzz-impostor-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        copy_tree(&source, &dir);
        terramp::texcell::save(&dir, &small_sample()).expect("the forest sample");
        let mut relative = Vec::new();
        walk(&dir, &dir, &mut relative);
        relative.sort_by(|a, b| a.as_os_str().as_encoded_bytes().cmp(b.as_os_str().as_encoded_bytes()));
        let files = relative
            .into_iter()
            .map(|path| {
                let bytes = std::fs::read(dir.join(&path)).expect("a template file");
                (path, bytes)
            })
            .collect();
        let models = terramp::impostor::models(&dir).expect("the template's models");
        Template { dir, files, models }
    })
}

fuzz_target!(
    init: {
        build_checks::probe();
        if let Some(seeds) = std::env::var_os("TERRAMP_FUZZ_SEEDS") {
            let seeds = PathBuf::from(seeds);
            std::fs::create_dir_all(&seeds).expect("the seeds' folder");
            for (index, (path, bytes)) in template().files.iter().enumerate() {
                let name = path.to_string_lossy().replace('/', "_");
                let mut seed = vec![index as u8];
                seed.extend_from_slice(bytes);
                std::fs::write(seeds.join(format!("{index}-{name}")), seed).expect("a seed");
            }
            std::process::exit(0);
        }
    },
    |bytes: &[u8]| {
        let template = template();
        let Some((&pick, content)) = bytes.split_first() else { return };
        let (path, original) = &template.files[usize::from(pick) % template.files.len()];
        let target = template.dir.join(path);
        std::fs::write(&target, content).expect("writing the changed file");
        for model in &template.models {
            let _ = terramp::impostor::load(&template.dir, model);
        }
        let _ = terramp::texcell::load(&template.dir, CLASS);
        std::fs::write(&target, original).expect("putting the file back");
    }
);
