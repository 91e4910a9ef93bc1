//! The render of `nc/` (DEM, Landsat imagery, land cover) from a fixed camera is not blank and
//! matches the reference image within a tolerance. Regenerate the reference after an intended
//! change of the look with `TERRAMP_BLESS=1 cargo test -p terramp-data-tools --test render_nc`.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp::gpu::{AdapterChoice, Gpu};

use support::{build_nc, tests_dir};
use terramp_testkit::{TempDir, shared_data};

const REFERENCE: &str = "reference/nc_240x135.png";
/// Rasterisers differ in the last bits of filtering and coverage; a broken frame is far below this.
const MIN_PSNR_DB: f64 = 30.0;

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
        fov_deg: 60.0,
        near_m: 0.1,
    };
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter (install mesa-vulkan-drivers)");
    let mut renderer = Renderer::new(gpu, dataset, settings).unwrap();
    let (report, frames) = renderer.render_resolved(&camera, 200).unwrap();
    assert!(renderer.is_resolved(&report), "not resolved after {frames} frames: {report:?}");
    assert!(report.nodes_drawn > 0 && report.imagery.needed_resident > 0, "{report:?}");
    let image = renderer.read_colour().unwrap();

    // Not blank: the lower half is ground (depth written), and it is not one flat colour.
    let depth = renderer.read_depth().unwrap();
    assert!(depth[depth.len() / 2..].iter().all(|&d| d > 0.0));
    let lower: Vec<u32> = image.pixels().skip(image.pixels().len() / 2).map(|p| u32::from(p[1])).collect();
    assert!(lower.iter().max().unwrap() - lower.iter().min().unwrap() > 40);

    terramp_testkit::check_reference(&image, &tests_dir(), REFERENCE, MIN_PSNR_DB, dir.path());
}
