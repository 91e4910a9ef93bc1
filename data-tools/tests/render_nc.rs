//! The render of `nc/` (DEM, Landsat imagery, land cover) from a fixed camera is not blank and
//! matches its reference image (`terramp_testkit::Golden`); a control frame, the same view from a
//! camera moved by `CONTROL_SHIFT_M`, must miss it by far. After an intended change of the look,
//! `scripts/bless_references.sh` makes the last rendered frame the reference.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::Renderer;

use support::{build_nc, tests_dir};
use terramp_testkit::{Golden, TempDir, shared_data};

const REFERENCE: &str = "reference/nc_240x135.png";
/// lavapipe renders this frame 69.7 dB from the reference an earlier renderer blessed (measured
/// 2026-12-06); the tolerance leaves room for another build's last bits of filtering and coverage
/// only.
const MIN_PSNR_DB: f64 = 60.0;
/// The control: the same view from 3 m further east, a third of a pixel's ground footprint there
/// (45.4 dB from the reference): a regression that small must fail.
const CONTROL_SHIFT_M: f64 = 3.0;

#[test]
fn nc_renders_like_its_reference() {
    if shared_data().is_none() {
        return;
    }
    let dir = TempDir::new("render-nc");
    let dataset = build_nc(&dir.path().join("nc"));
    let mut settings = Settings::default();
    settings.render.width = 240;
    settings.render.height = 135;
    let camera = Camera {
        position_m: DVec3::new(631_000.0, 216_000.0, 1500.0),
        yaw_deg: 40.0,
        pitch_deg: -25.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: 0.1,
    };
    let gpu = terramp_testkit::gpu();
    let mut renderer = Renderer::new(gpu, dataset, settings).unwrap();
    let (report, frames) = renderer.render_resolved(&camera).unwrap();
    assert!(renderer.is_resolved(&report), "not resolved after {frames} frames: {report:?}");
    assert!(report.nodes_drawn > 0 && report.imagery.needed_resident > 0, "{report:?}");
    let image = renderer.read_colour().unwrap();

    // Not blank: the lower half is ground (depth written), and it is not one flat colour.
    let depth = renderer.read_depth().unwrap();
    assert!(depth[depth.len() / 2..].iter().all(|&d| d > 0.0));
    let lower: Vec<u32> = image.pixels().skip(image.pixels().len() / 2).map(|p| u32::from(p[1])).collect();
    assert!(lower.iter().max().unwrap() - lower.iter().min().unwrap() > 40);

    let shifted = Camera { position_m: camera.position_m + DVec3::X * CONTROL_SHIFT_M, ..camera };
    renderer.render_resolved(&shifted).unwrap();
    let control = renderer.read_colour().unwrap();
    let golden = Golden { tests_dir: &tests_dir(), name: REFERENCE, min_db: MIN_PSNR_DB };
    golden.check(&renderer.gpu, &image, &control);
}
