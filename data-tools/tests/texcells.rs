//! Texcells on `nc/` (DEM, Landsat, land use): the nc table's dense class (forest) gets a small
//! forest sample baked from the shared models, and a view from 350 m up across the forest to the
//! horizon (the view, heading 20°, pitched 8° down) is rendered with texcells and without
//! (`texcells.reach_m` 0, the control; no seed impostors, so nothing else differs). Under each
//! pixel, the frame without texcells gives the ground, its distance and its land-cover class:
//! texcells change most pixels of deep forest within their band, none nearer than the band (the
//! seeds' own), and no pixel of open water (water whose land-cover neighbourhood holds no forest
//! and that no forest in front of it could reach up to).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use glam::DVec3;
use terramp::bake::forest::{ForestOptions, bake_forests};
use terramp::camera::Camera;
use terramp::classes::ClassTable;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::{FrameReport, Renderer};
use terramp::gpu::{AdapterChoice, Gpu};
use terramp_testkit::{TempDir, shared_data};

use support::{PixelGround, build_nc, code_at, ground_under_pixels};

const FOREST: u8 = 5;
const WATER: u8 = 6;
const SIZE: [u32; 2] = [480, 270];
/// The view: CRS east, north, altitude (metres), heading and pitch (degrees).
const VIEW: [f64; 5] = [636_500.0, 216_500.0, 350.0, 20.0, -8.0];
const REACH_M: f64 = 8000.0;

/// The nc table's forest sample, baked once per test process (small: 128 texels, 16 slices).
fn samples() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("texcells-samples");
        let models = shared_data().expect("../shared/data").join("models");
        let table = ClassTable::load("nc").unwrap();
        let options = ForestOptions { texels: 128, slices: 16, ..ForestOptions::default() };
        let gpu = Gpu::new(AdapterChoice::Auto).unwrap();
        let baked = bake_forests(Some(&gpu), &table, &models, &out, &options, &mut |_| {}).unwrap();
        assert_eq!(baked.iter().map(|r| r.class_code).collect::<Vec<_>>(), [FOREST]);
        out
    })
}

fn render(dataset: Dataset, reach_m: f64) -> (image::RgbaImage, Vec<f32>, FrameReport, Camera) {
    let mut settings = Settings::preset("balanced").unwrap();
    [settings.render.width, settings.render.height] = SIZE;
    settings.draw_seeds.impostors = samples().display().to_string();
    settings.texcells.reach_m = reach_m;
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter (install mesa-vulkan-drivers)");
    let mut r = Renderer::new(gpu, dataset, settings).unwrap();
    let [x, y, z, yaw, pitch] = VIEW;
    let camera = terramp_testkit::camera::looking(DVec3::new(x, y, z), yaw, pitch);
    r.render_resolved(&camera).unwrap();
    // The land cover under the texcells streams a frame after they are placed.
    let mut report = r.render(&camera).unwrap();
    for _ in 0..6 {
        report = r.render(&camera).unwrap();
    }
    (r.read_colour().unwrap(), r.read_depth().unwrap(), report, camera)
}

#[test]
fn nc_texcells_cover_the_far_forest_and_no_water() {
    if shared_data().is_none() {
        return;
    }
    let dir = TempDir::new("texcells-nc");
    let dataset = build_nc(dir.path());
    let (bare, depth, bare_report, camera) = render(Dataset::open(dir.path()).unwrap(), 0.0);
    let (forest, _, report, _) = render(dataset, REACH_M);
    assert_eq!(bare_report.texcells.slices, 0, "the control draws no texcells");
    let t = report.texcells;
    println!("texcells: {} patches, {} slices", t.patches, t.slices);
    assert!(t.patches > 0 && t.slices > t.patches, "{t:?}");

    let reopened = Dataset::open(dir.path()).unwrap();
    let ground = ground_under_pixels(&reopened, &camera, SIZE, &depth);
    let changed = |i: usize| {
        let (a, b) = (&bare.as_raw()[4 * i..4 * i + 3], &forest.as_raw()[4 * i..4 * i + 3]);
        a.iter().zip(b).any(|(a, b)| a.abs_diff(*b) > 2)
    };
    // Whether a texel's 3 × 3 neighbourhood is all of `code`, all free of it.
    let neighbourhood = |q: [u32; 2], all: bool, code: u8| {
        (-1i64..=1).flat_map(|j| (-1i64..=1).map(move |i| (i, j))).all(|(i, j)| {
            let at = [q[0] as i64 + i, q[1] as i64 + j];
            let c = (at[0] >= 0 && at[1] >= 0)
                .then(|| code_at(&reopened, [at[0] as u32, at[1] as u32]))
                .flatten();
            (c == Some(code)) == all
        })
    };
    let band = terramp::passes::texcells::frame::Band::of(&{
        let mut s = Settings::preset("balanced").unwrap();
        s.texcells.reach_m = REACH_M;
        s
    });
    // Forest pixels that a texcell slab standing in front could cover: up to its height above the
    // ground in pixels at that distance, over any ground.
    let [w, h] = SIZE;
    let slab_m = 40.0;
    let mut shadow = vec![false; (w * h) as usize];
    for (i, g) in ground.iter().enumerate() {
        let Some(PixelGround { code, distance_m, .. }) = *g else { continue };
        if code != FOREST {
            continue;
        }
        let reach_px = (slab_m / camera.metres_per_pixel(distance_m, h)).ceil() as i64 + 1;
        let (x, y) = ((i as u32 % w) as i64, (i as u32 / w) as i64);
        for yy in (y - reach_px).max(0)..=y {
            shadow[(yy * i64::from(w) + x) as usize] = true;
        }
    }
    let (mut deep, mut deep_changed, mut water, mut water_changed, mut near, mut near_changed) =
        (0, 0, 0, 0, 0, 0);
    for (i, g) in ground.iter().enumerate() {
        let Some(g) = *g else { continue };
        let inside = g.distance_m > band.fade_in_m + band.fade_in_width_m
            && g.distance_m < band.reach_m - band.fade_out_width_m;
        if g.code == FOREST && inside && neighbourhood(g.texel, true, FOREST) {
            deep += 1;
            deep_changed += usize::from(changed(i));
        }
        if g.code == WATER && !shadow[i] && neighbourhood(g.texel, false, FOREST) {
            water += 1;
            water_changed += usize::from(changed(i));
        }
        if g.distance_m < band.fade_in_m - 200.0 && !shadow[i] {
            near += 1;
            near_changed += usize::from(changed(i));
        }
    }
    println!(
        "deep forest in the band: {deep_changed} of {deep} changed; open water: {water_changed} of {water}; nearer than the band: {near_changed} of {near}"
    );
    assert!(
        deep > 300 && deep_changed * 10 >= deep * 9,
        "{deep_changed} of {deep} deep-forest pixels show texcells"
    );
    assert!(water > 50, "only {water} pixels of open water in view: a weak test");
    assert_eq!(water_changed, 0, "texcells over open water");
    assert!(near > 1000, "only {near} pixels nearer than the band");
    assert_eq!(near_changed, 0, "texcells nearer than their band");
}
