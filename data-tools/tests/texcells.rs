//! Texcells on `nc/` (DEM, Landsat, land use): the nc table's dense class (forest) gets a small
//! forest sample baked from the shared models, and a view from 350 m up over the map's centre
//! towards the most water 3.5–6.5 km away (pitched 4° down) is rendered with texcells and without
//! (`texcells.reach_m` 0, the control; no seed impostors, so nothing else differs). Under each
//! pixel, the frame without texcells gives the ground, its distance and its land-cover class:
//! texcells change most pixels of deep forest within their band, none nearer than the band (the
//! seeds' own), and no pixel of open water (water whose land-cover neighbourhood holds no forest
//! and that no forest in front of it could reach up to).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use terramp::bake::forest::{ForestOptions, bake_forests};
use terramp::camera::Camera;
use terramp::classes::ClassTable;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::{FrameReport, Renderer};
use terramp::gpu::{AdapterChoice, Gpu};
use terramp_testkit::{TempDir, shared_data};

use support::{FOREST, PixelGround, WATER, build_nc, code_at, ground_under_pixels};

const SIZE: [u32; 2] = [480, 270];
/// The camera's height above the ground at the map's centre, and its pitch.
const VIEW: [f64; 2] = [350.0, -4.0];
/// Where the view looks for water: inside the texcell band.
const WATER_AT_M: [f64; 2] = [3500.0, 6500.0];
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

/// The map's centre, and the heading (degrees, of 36) whose sight line crosses the most water
/// within `WATER_AT_M` of it.
fn towards_far_water(dataset: &Dataset) -> ([f64; 2], f64) {
    let [w, h] = dataset.manifest.extent_m();
    let centre = [w / 2.0, h / 2.0];
    let texel_m = 2.0 * dataset.manifest.landcover.as_ref().unwrap().layer.texel_m;
    let water_along = |yaw: f64| {
        let (sin, cos) = yaw.to_radians().sin_cos();
        (0..60)
            .map(|k| WATER_AT_M[0] + (WATER_AT_M[1] - WATER_AT_M[0]) * f64::from(k) / 60.0)
            .filter(|d| {
                let p = [centre[0] + d * sin, centre[1] + d * cos];
                (p[0] >= 0.0 && p[1] >= 0.0)
                    && code_at(dataset, [(p[0] / texel_m) as u32, (p[1] / texel_m) as u32]) == Some(WATER)
            })
            .count()
    };
    let yaw = (0..36).map(|k| f64::from(k) * 10.0).max_by_key(|&yaw| water_along(yaw)).unwrap();
    assert!(water_along(yaw) > 0, "no water {WATER_AT_M:?} m from nc's centre");
    (centre, yaw)
}

fn render(dataset: Dataset, reach_m: f64) -> (image::RgbaImage, Vec<f32>, FrameReport, Camera) {
    let mut settings = Settings::preset("balanced").unwrap();
    [settings.render.width, settings.render.height] = SIZE;
    settings.draw_seeds.impostors = samples().display().to_string();
    settings.texcells.reach_m = reach_m;
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter (install mesa-vulkan-drivers)");
    let mut r = Renderer::new(gpu, dataset, settings).unwrap();
    let [above_m, pitch] = VIEW;
    let (centre, yaw) = towards_far_water(&r.dataset);
    let camera = terramp_testkit::camera::over(&r, centre, above_m, yaw, pitch);
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
    let path = dir.path().join("nc");
    let dataset = build_nc(&path);
    let (bare, depth, bare_report, camera) = render(Dataset::open(&path).unwrap(), 0.0);
    let (forest, _, report, _) = render(dataset, REACH_M);
    assert_eq!(bare_report.texcells.slices, 0, "the control draws no texcells");
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR"));
    bare.save(shots.join("texcells_nc_without.png")).unwrap();
    forest.save(shots.join("texcells_nc_with.png")).unwrap();
    let t = report.texcells;
    println!("texcells: {} patches, {} slices", t.patches, t.slices);
    assert!(t.patches > 0 && t.slices > t.patches, "{t:?}");

    let reopened = Dataset::open(&path).unwrap();
    let ground = ground_under_pixels(&reopened, &camera, SIZE, &depth);
    let changed = |i: usize| {
        let (a, b) = (&bare.as_raw()[4 * i..4 * i + 3], &forest.as_raw()[4 * i..4 * i + 3]);
        a.iter().zip(b).any(|(a, b)| a.abs_diff(*b) > 2)
    };
    // Whether the texels within `r` of a texel are all of `code`, or all free of it.
    let neighbourhood = |q: [u32; 2], r: i64, all: bool, code: u8| {
        (-r..=r).flat_map(|j| (-r..=r).map(move |i| (i, j))).all(|(i, j)| {
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
        // A far pixel spans several texels: its neighbourhood grows with its footprint.
        let texel_m = 2.0 * reopened.manifest.landcover.as_ref().unwrap().layer.texel_m;
        let r = 1 + (camera.metres_per_pixel(g.distance_m, h) / texel_m).ceil() as i64;
        if g.code == FOREST && inside && neighbourhood(g.texel, 1, true, FOREST) {
            deep += 1;
            deep_changed += usize::from(changed(i));
        }
        if g.code == WATER && !shadow[i] && neighbourhood(g.texel, r, false, FOREST) {
            water += 1;
            water_changed += usize::from(changed(i));
            if changed(i) {
                println!(
                    "water pixel ({}, {}) at {:.0} m: {:?} → {:?}",
                    i as u32 % w,
                    i as u32 / w,
                    g.distance_m,
                    &bare.as_raw()[4 * i..4 * i + 3],
                    &forest.as_raw()[4 * i..4 * i + 3]
                );
            }
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
