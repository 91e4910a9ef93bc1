//! The host's questions about the ground (`Renderer::drawn_ground`, `ground_at`,
//! `plants_near`), answered on the CPU and held to what the GPU drew (`terramp_testkit::query`):
//! a pick through a pixel's centre lands where the depth buffer says that pixel's ground is,
//! within the depth buffer's precision; the drawn ground's height under a picked point is the
//! pick's; the plants pass 3 keeps near a point are the seeds it wrote there; on the finest data,
//! the height is the dataset's. nc and zion: `data-tools/tests/query_real.rs`.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::frame::Renderer;
use terramp::gpu::Gpu;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::query::{picks, plants};
use terramp_testkit::{camera, gpu, renderer, small_settings, synth_dataset};

const SIZE: [u32; 2] = [320, 180];

#[test]
fn picks_land_where_the_depth_buffer_has_the_ground() {
    let dir = synth_dataset(300, 7);
    let mut r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    for (what, pose) in [
        ("synthetic, 25 m up, looking along", camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0)),
        ("synthetic, 600 m up, looking down", camera::over_fraction(&r, [0.3, 0.3], 600.0, 45.0, -35.0)),
    ] {
        picks(&mut r, &pose).check(what);
    }
}

#[test]
fn picks_land_where_the_depth_buffer_has_the_ground_on_the_earth() {
    let dataset = synth_on_nc(512, 30.0, 11);
    let gpu: Gpu = gpu();
    let mut r = Renderer::new(gpu, dataset, small_settings(SIZE[0], SIZE[1])).unwrap();
    let pose = camera::over_fraction(&r, [0.2, 0.2], 2_000.0, 45.0, -8.0);
    picks(&mut r, &pose).check("synthetic on nc's State Plane, on the Earth, 2 km up");
}

#[test]
fn the_finest_grounds_height_is_the_datasets() {
    let dir = synth_dataset(300, 7);
    let r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    let spacing_m = r.dataset.manifest.height.spacing_m;
    for (i, j) in [(3u32, 5u32), (100, 40), (250, 299)] {
        let at = r.ground_at(f64::from(i) * spacing_m, f64::from(j) * spacing_m).unwrap();
        assert_eq!(at.height_m, r.dataset.height_sample(0, i, j).unwrap());
        assert!((at.normal.length() - 1.0).abs() < 1e-12 && at.normal.z > 0.0);
    }
    // A plane's normal: between samples, the triangle's, which points away from the rise.
    let at = r.ground_at(100.5 * spacing_m, 40.25 * spacing_m).unwrap();
    let east = r.ground_at(100.75 * spacing_m, 40.25 * spacing_m).unwrap();
    let rise = east.height_m - at.height_m;
    assert!(rise == 0.0 || (at.normal.x < 0.0) == (rise > 0.0), "{at:?} {rise}");
}

#[test]
fn the_plants_near_a_point_are_the_seeds_pass_3_selected_there() {
    let dir = synth_dataset(300, 7);
    let mut r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    let pose = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
    plants(&mut r, &pose).check("synthetic, 25 m up");
}
