//! Large coordinates. The renderer works in grid space (CRS metres minus the dataset's origin, in
//! f64) and hands the GPU only camera-relative f32 offsets, so moving a dataset to UTM-like
//! (500 000 E, 5 000 000 N) or 10⁷ m offsets must change neither a pixel nor a seed; and inside a
//! planet-size dataset, 10⁷ m from its own origin, seeds must still stand where their pattern puts
//! them, to the centimetre.

use glam::DVec3;
use terramp::camera::Camera;
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::SeedRecord;
use terramp::reference::worst::max_or_nan;
use terramp::seeds::cell_pattern;
use terramp::synth::SynthParams;

use terramp_testkit::audit::{Dem, Tolerance, audit, camera_at};
use terramp_testkit::small_settings;

const ORIGINS_M: [[f64; 2]; 3] = [[0.0, 0.0], [500_000.0, 5_000_000.0], [1e7, 1e7]];

/// Most a seed may stand from its exact pattern position, or move between origins, metres: the
/// promise, to the centimetre; f32 camera-relative offsets put it within a third of a millimetre
/// (0.12 and 0.28 mm measured, docs/README.md), where f32 grid coordinates 10⁷ m out would be off
/// by up to a metre.
const MAX_PLACEMENT_M: f64 = 0.01;

/// Camera poses in grid space (x, y, metres above the ground, yaw, pitch), with fractions of a
/// millimetre no f64 sum at 10⁷ m carries exactly.
const POSES: [[f64; 5]; 2] =
    [[1130.4567, 1021.2345, 40.0, 35.0, -10.0], [1402.9876, 1489.1111, 3.0, 290.0, 2.0]];

struct Frame {
    image: image::RgbaImage,
    /// Sorted by (cell, rank).
    seeds: Vec<SeedRecord>,
    camera_grid_m: DVec3,
}

fn camera(r: &Renderer, dem: &Dem, [x, y, above_m, yaw_deg, pitch_deg]: [f64; 5]) -> Camera {
    camera_at(r, dem, [x, y], above_m, yaw_deg, pitch_deg)
}

/// The largest distance between a seed's position (grid space, from the GPU's camera-relative
/// record) and where its pattern puts it (f64, exact).
fn worst_placement_error_m(r: &Renderer, seeds: &[SeedRecord], camera_grid_m: DVec3) -> f64 {
    let (_, patterns) = r.seed_world().unwrap();
    let tlm = &r.settings.tlm;
    let spp = patterns.seeds_per_pattern;
    seeds
        .iter()
        .map(|s| {
            let pattern = cell_pattern(s.address, tlm.seed, tlm.corner_colours());
            let unit = patterns.positions_unit[(pattern * spp + s.rank) as usize];
            let exact = [0, 1].map(|a| (f64::from(s.address[a]) + f64::from(unit[a])) * tlm.cell_m);
            let gpu = [0, 1].map(|a| camera_grid_m[a] + f64::from(s.position_rel_m[a]));
            (gpu[0] - exact[0]).hypot(gpu[1] - exact[1])
        })
        .fold(0.0, max_or_nan)
}

fn render(origin_m: [f64; 2], pose: [f64; 5]) -> Frame {
    let params = SynthParams { size: 256, seed: 7, origin_m, ..Default::default() };
    let dataset = terramp_testkit::synth_dataset_with(&params);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(320, 180));
    let dem = Dem::load(&r.dataset);
    let camera = camera(&r, &dem, pose);
    r.render_resolved(&camera).unwrap();
    let what = format!("origin {origin_m:?}, pose {pose:?}");
    let a = audit(&r, &camera, &dem, Tolerance::flat(0.1, 20.0), 4);
    a.assert_sound(&what);
    let (mut seeds, _) = r.read_seeds().unwrap().unwrap();
    seeds.sort_by_key(|s| (s.address, s.rank));
    let o = r.dataset.manifest.origin_m;
    let camera_grid_m = camera.position_m - DVec3::new(o[0], o[1], 0.0);
    let placement_m = worst_placement_error_m(&r, &seeds, camera_grid_m);
    println!("{what}: {} seeds, placement error {:.2e} m, {a:?}", seeds.len(), placement_m);
    assert!(placement_m <= MAX_PLACEMENT_M, "{what}: a seed is {placement_m} m from its pattern position");
    Frame { image: r.read_colour().unwrap(), seeds, camera_grid_m }
}

#[test]
fn utm_and_1e7_offsets_render_the_same_image_and_seeds() {
    for pose in POSES {
        let at_origin = render(ORIGINS_M[0], pose);
        assert!(at_origin.seeds.len() > 100, "{} seeds", at_origin.seeds.len());
        for origin in &ORIGINS_M[1..] {
            let moved = render(*origin, pose);
            let differing =
                at_origin.image.pixels().zip(moved.image.pixels()).filter(|(a, b)| a != b).count();
            let psnr = terramp_testkit::psnr(&at_origin.image, &moved.image);
            // The same seeds, each at the same place relative to the dataset.
            let id = |s: &SeedRecord| (s.address, s.rank, s.species_lod);
            assert!(at_origin.seeds.iter().map(id).eq(moved.seeds.iter().map(id)), "{origin:?}: other seeds");
            let mut worst_m = 0.0f64;
            for (a, b) in at_origin.seeds.iter().zip(&moved.seeds) {
                for axis in 0..3 {
                    let pa = at_origin.camera_grid_m[axis] + f64::from(a.position_rel_m[axis]);
                    let pb = moved.camera_grid_m[axis] + f64::from(b.position_rel_m[axis]);
                    worst_m = max_or_nan(worst_m, (pa - pb).abs());
                }
                worst_m = max_or_nan(worst_m, f64::from((a.ground_m - b.ground_m).abs()));
            }
            println!(
                "{origin:?}: {differing} pixels differ (PSNR {psnr:.1} dB), seeds moved ≤ {worst_m:.2e} m"
            );
            assert!(worst_m <= MAX_PLACEMENT_M, "{origin:?}: a seed moved {worst_m} m");
            assert_eq!(differing, 0, "{origin:?}: the image changed (PSNR {psnr:.1} dB)");
        }
    }
}

#[test]
fn a_planet_size_dataset_places_seeds_to_the_centimetre_10_million_metres_out() {
    // 257 samples 39 km apart: 10 000 km on a side, the camera 5 000 km from the origin.
    let params = SynthParams { size: 257, seed: 3, spacing_m: 39_062.5, ..Default::default() };
    let dataset = terramp_testkit::synth_dataset_with(&params);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(320, 180));
    let dem = Dem::load(&r.dataset);
    let mut grown = 0;
    for (k, grid) in [[5.0e6, 5.0e6], [5.3e6, 4.7e6], [9.7e6, 9.8e6], [2.2e6, 7.9e6]].iter().enumerate() {
        let pose = [grid[0] + 0.4567, grid[1] + 0.891, 3.0, 40.0 + 70.0 * k as f64, -8.0];
        let camera = camera(&r, &dem, pose);
        r.render_resolved(&camera).unwrap();
        let a = audit(&r, &camera, &dem, Tolerance::flat(1.0, 100.0), 4);
        a.assert_sound(&format!("pose {pose:?}"));
        let (seeds, _) = r.read_seeds().unwrap().unwrap();
        let camera_grid_m = DVec3::new(pose[0], pose[1], camera.position_m.z);
        let placement_m = worst_placement_error_m(&r, &seeds, camera_grid_m);
        println!("pose {pose:?}: {} seeds, placement error {placement_m:.2e} m, {a:?}", seeds.len());
        assert!(placement_m <= MAX_PLACEMENT_M, "a seed is {placement_m} m from its pattern position");
        grown += seeds.len();
    }
    assert!(grown > 100, "only {grown} seeds: the test saw no land that grows any");
}
