//! Helpers of the texcell tests: the nc table's forest sample baked once per test process, a
//! texcell frame rendered and settled, and which pixels texcells changed.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use terramp::bake::forest::{ForestOptions, bake_forests};
use terramp::camera::Camera;
use terramp::classes::ClassTable;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::{FrameReport, Renderer};
use terramp_testkit::shared_data;

use super::FOREST;

/// The frames' size.
pub const SIZE: [u32; 2] = [480, 270];

/// The nc table's forest sample, baked once per test process (small: 128 texels, 16 slices).
pub fn samples() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("texcells-samples");
        let models = shared_data().expect("../shared/data").join("models");
        let table = ClassTable::load("nc").unwrap();
        let options = ForestOptions { texels: 128, slices: 16, ..ForestOptions::default() };
        let gpu = terramp_testkit::gpu();
        let baked = bake_forests(Some(&gpu), &table, &models, &out, &options, &mut |_| {}).unwrap();
        assert_eq!(baked.iter().map(|r| r.class_code).collect::<Vec<_>>(), [FOREST]);
        out
    })
}

/// Settings that draw the trees and the texcells in their models' own colours (the colour
/// follow-up off: `texcells.ground_blend` and every nc species' `ground_blend` 0). Following the
/// photograph, the forest's mean colour is the ground's by design, so whether a pixel changed from
/// the bare ground no longer tells where the forest is drawn; in the models' colours it does.
pub fn own_colours(settings: &mut Settings) {
    static TABLE: OnceLock<PathBuf> = OnceLock::new();
    let table = TABLE.get_or_init(|| terramp_testkit::nc_table_with("nc-own-colours", "ground_blend = 0.0"));
    settings.texcells.ground_blend = 0.0;
    settings.seeds.class_table = table.display().to_string();
}

/// A rendered, settled frame: the renderer, its colour, its depth, its report and its camera.
pub type Frame = (Renderer, image::RgbaImage, Vec<f32>, FrameReport, Camera);

/// Renders `dataset` at `SIZE` with the balanced preset, the impostors (and forest samples) in
/// `impostors`, texcells to `reach_m` (0: none) and whatever `tune` changes, from the camera
/// `camera_of` places in the renderer, settled (the land cover under the texcells streams a frame
/// after they are placed).
pub fn render_from(
    dataset: Dataset,
    impostors: &Path,
    reach_m: f64,
    tune: &dyn Fn(&mut Settings),
    camera_of: &dyn Fn(&Renderer) -> Camera,
) -> Frame {
    let mut settings = Settings::preset("balanced").unwrap();
    [settings.render.width, settings.render.height] = SIZE;
    settings.draw_seeds.impostors = impostors.display().to_string();
    settings.texcells.reach_m = reach_m;
    tune(&mut settings);
    let gpu = terramp_testkit::gpu();
    let mut r = Renderer::new(gpu, dataset, settings).unwrap();
    let camera = camera_of(&r);
    r.render_resolved(&camera).unwrap();
    let mut report = r.render(&camera).unwrap();
    for _ in 0..6 {
        report = r.render(&camera).unwrap();
    }
    let (colour, depth) = (r.read_colour().unwrap(), r.read_depth().unwrap());
    (r, colour, depth, report, camera)
}

/// Whether texcells changed pixel `i` of `bare` in `forest` (by more than rounding).
pub fn changed(bare: &image::RgbaImage, forest: &image::RgbaImage, i: usize) -> bool {
    let (a, b) = (&bare.as_raw()[4 * i..4 * i + 3], &forest.as_raw()[4 * i..4 * i + 3]);
    a.iter().zip(b).any(|(a, b)| a.abs_diff(*b) > 2)
}

/// The nc table's species as impostors and its forest sample beside them, baked once per test
/// process through the command line (`terramp-data bake --model ... --classes nc`).
pub fn trees_and_forest() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("texcells-trees-and-forest");
        let models = shared_data().expect("../shared/data").join("models");
        let table = ClassTable::load("nc").unwrap();
        let mut bake = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data"));
        bake.arg("bake");
        for s in &table.species {
            bake.arg("--model").arg(models.join(format!("{}.glb", s.model)));
        }
        bake.args(["--classes", "nc", "--texels", "256", "--models"]).arg(&models).arg("--out").arg(&out);
        let output = bake.output().unwrap();
        assert!(output.status.success(), "bake failed:\n{}", String::from_utf8_lossy(&output.stderr));
        out
    })
}
