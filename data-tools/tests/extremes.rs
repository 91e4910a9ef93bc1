//! The extremes of DESIGN.md that need real or hand-made rasters, each frame audited as in
//! `tests/extremes.rs` (the audit is shared: `support::audit`): depth, colour, Tile Load Map and
//! seed records read back and checked, holes and stray ground judged against rays through the DEM.
//!
//! - `rainier/`: SRTM voids (nodata), filled by the builder: seen from above, from the side and at
//!   a grazing angle, the filled ground has no hole, no spike, nothing non-finite.
//! - `zion/`: DEM nodata along the rotated borders and NLCD nodata: seeds grow up to the border
//!   and never on nodata land cover.
//! - A hand-made DEM with a vertical 300 m step between two flat plateaus, under forest: the cliff
//!   renders without holes seen from below, from above and at exactly 89.9° incidence on the flat
//!   ground, and no seed stands on its face.
//! - A one-pixel DEM builds and renders.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use gdal::GeoTransform;
use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;

use support::{build, build_zion, mask_image, write_geotiff};
use terramp_testkit::audit::{Audit, Dem, Tolerance, audit, camera_at};
use terramp_testkit::{TempDir, shared_data};

fn renderer(dataset: Dataset, width: u32, height: u32) -> Renderer {
    let mut settings = Settings::default();
    settings.render.width = width;
    settings.render.height = height;
    let gpu = terramp_testkit::gpu();
    Renderer::new(gpu, dataset, settings).unwrap()
}

/// Renders `camera` until resolved, audits the frame and checks it is sound, and that at least
/// `min_ground` of the rays judged must meet the ground.
fn render_and_audit(
    r: &mut Renderer,
    dem: &Dem,
    what: &str,
    camera: &Camera,
    tol: Tolerance,
    min_ground: usize,
) -> Audit {
    r.render_resolved(camera).unwrap();
    let a = audit(r, camera, dem, tol, 4);
    println!("{what}: {a:?}");
    a.assert_sound(what);
    assert!(a.expect_ground >= min_ground, "{what}: the rays meet too little ground ({a:?})");
    a
}

/// The centre of the largest cluster of filled samples at least `margin` samples from the edges:
/// the sample with the most filled samples in the 15 × 15 window around it.
fn largest_void(dataset: &Dataset, margin: u32) -> Option<[u32; 2]> {
    let mask = mask_image(dataset);
    let [w, h] = dataset.height.pyramid.size;
    let filled = |x: u32, y: u32| u32::from(mask[(y * w + x) as usize] == 0);
    let mut best = (0, None);
    for y in (margin..h - margin).step_by(3) {
        for x in (margin..w - margin).step_by(3) {
            if filled(x, y) == 0 {
                continue;
            }
            let count: u32 = (y - 7..=y + 7)
                .flat_map(|j| (x - 7..=x + 7).map(move |i| (i, j)))
                .map(|(i, j)| filled(i, j))
                .sum();
            if count > best.0 {
                best = (count, Some([x, y]));
            }
        }
    }
    println!("largest void: {} of 225 samples filled around {:?}", best.0, best.1);
    best.1
}

#[test]
fn rainier_voids_render_without_holes_or_spikes() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("extremes-rainier");
    let dem_path = data.join("rainier/mt_rainier_90m.tif");
    let (dataset, _) = build(&tmp.path().join("rainier"), &["--dem", dem_path.to_str().unwrap()]);
    assert!(dataset.manifest.height.filled_samples > 1000);
    let void = largest_void(&dataset, 100).expect("a void away from the edges");
    let mut r = renderer(dataset, 320, 180);
    let dem = Dem::load(&r.dataset);
    let spacing_m = dem.spacing_m;
    let c = void.map(|v| f64::from(v) * spacing_m);
    // The relief is steep (Mount Rainier): beyond the finest LOD's range the coarse levels stand up
    // to 232 m off the finest mesh (a pixel or two, far away), so the rays are judged with 300 m
    // of slack there; a hole or a nodata spike would be far more (a -32768 spike, 33 km).
    let tol = Tolerance { height_m: 0.05, coarse_height_m: 300.0, margin_m: 3.0 * spacing_m };
    let views = [
        ("above the void", camera_at(&r, &dem, [c[0], c[1] - 3000.0], 1500.0, 0.0, -35.0)),
        ("straight down on the void", camera_at(&r, &dem, c, 800.0, 0.0, -90.0)),
        ("2 m up, level, towards the void", camera_at(&r, &dem, [c[0] - 1500.0, c[1]], 2.0, 90.0, 0.0)),
        ("2 m up, 0.1° down, across the void", camera_at(&r, &dem, [c[0], c[1] + 1200.0], 2.0, 180.0, -0.1)),
    ];
    for (what, camera) in views {
        render_and_audit(&mut r, &dem, what, &camera, tol, 50);
    }
}

#[test]
fn zion_seeds_grow_up_to_the_nodata_border_and_never_on_it() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("extremes-zion");
    let dataset = build_zion(&tmp.path().join("zion"));
    let landcover = dataset.manifest.landcover.clone().unwrap();
    let nodata = landcover.nodata_code;
    let mask = mask_image(&dataset);
    let [w, h] = dataset.height.pyramid.size;
    // Along the middle row, the first valid sample from the west: the rotated border.
    let row = h / 2;
    let border = (0..w).find(|&x| mask[(row * w + x) as usize] == 1).expect("a valid sample");
    assert!(border > 5, "no nodata west of the middle row");
    let mut r = renderer(dataset, 320, 180);
    let dem = Dem::load(&r.dataset);
    let spacing_m = dem.spacing_m;
    let b = [f64::from(border) * spacing_m, f64::from(row) * spacing_m];
    // The coarse levels' worst error over the judged pixels: 46.9 m flat, 50.9 m on the Earth
    // (the far pixels fall on other points of the same coarse mesh, 30 m lower at 20 km).
    let tol = Tolerance { height_m: 0.05, coarse_height_m: 60.0, margin_m: 3.0 * spacing_m };
    let views = [
        ("inside, towards the border", camera_at(&r, &dem, [b[0] + 250.0, b[1]], 30.0, 270.0, -12.0)),
        ("over the border, looking in", camera_at(&r, &dem, [b[0] - 150.0, b[1] + 50.0], 20.0, 80.0, -10.0)),
    ];
    let (texel_m, half_m) = (2.0 * landcover.layer.texel_m, 0.5 * spacing_m);
    let size = r.dataset.landcover.as_ref().unwrap().pyramid.size_at(1);
    let code_at =
        |r: &Renderer, q: [u32; 2]| landcover.coding.code_of(r.dataset.landcover_index(1, q).unwrap());
    let mut grown = 0;
    for (what, camera) in views {
        let a = render_and_audit(&mut r, &dem, what, &camera, tol, 50);
        let (records, _) = r.read_seeds().unwrap().unwrap();
        let placing = r.exact_placing(&camera);
        let mut near_border = 0;
        for s in &records {
            let grid = placing.grid_m(DVec3::from(s.position_rel_m.map(f64::from)));
            let p = [grid.x, grid.y];
            let q = p.map(|v| ((v + half_m) / texel_m).floor() as u32);
            let code = code_at(&r, q);
            assert!(code.is_some_and(|c| c != nodata), "{what}: a seed grew on {code:?} at {p:?}");
            // Within three land-cover texels of a nodata one.
            let near = (q[1].saturating_sub(3)..=(q[1] + 3).min(size[1] - 1))
                .flat_map(|y| (q[0].saturating_sub(3)..=(q[0] + 3).min(size[0] - 1)).map(move |x| [x, y]))
                .any(|n| code_at(&r, n) == Some(nodata));
            near_border += usize::from(near);
        }
        println!("{what}: {} seeds, {near_border} within 3 texels of nodata land cover", a.seeds);
        grown += near_border;
    }
    assert!(grown > 0, "no seed near the border: the test saw nothing");
}

/// 10 m samples, EPSG:32633 (UTM 33N), north-up.
const CLIFF_GRID: GeoTransform = [500_000.0, 10.0, 0.0, 5_000_000.0, 0.0, -10.0];
const CLIFF_SIZE: [usize; 2] = [256, 64];
/// Samples west of this column are 100 m high, the rest 400 m: a 300 m step over one cell.
const CLIFF_COLUMN: usize = 128;

#[test]
fn a_vertical_cliff_renders_whole_and_grows_no_seed_on_its_face() {
    let tmp = TempDir::new("extremes-cliff");
    let [w, h] = CLIFF_SIZE;
    let heights: Vec<f32> = (0..w * h).map(|k| if k % w < CLIFF_COLUMN { 100.0 } else { 400.0 }).collect();
    let dem =
        write_geotiff(&tmp.path().join("cliff.tif"), CLIFF_SIZE, heights, CLIFF_GRID, 32633, Some(-9999.0));
    // Forest (nc code 5) everywhere.
    let forest = write_geotiff(
        &tmp.path().join("forest.tif"),
        CLIFF_SIZE,
        vec![5u8; w * h],
        CLIFF_GRID,
        32633,
        Some(255.0),
    );
    let args = ["--dem", dem.to_str().unwrap(), "--landcover", forest.to_str().unwrap(), "--classes", "nc"];
    let (dataset, _) = build(&tmp.path().join("out"), &args);
    let mut r = renderer(dataset, 320, 180);
    let dem = Dem::load(&r.dataset);
    let s = dem.spacing_m;
    let (foot, top) = ((CLIFF_COLUMN - 1) as f64 * s, CLIFF_COLUMN as f64 * s);
    let mid = 0.5 * dem.span_m()[1];
    // Over the flat low ground, high enough that a ray 0.1° down meets it 600 m out.
    let grazing_m = 600.0 * 0.1f64.to_radians().tan();
    let tol = Tolerance::flat(0.05, 20.0);
    let views = [
        ("facing the cliff from its foot", camera_at(&r, &dem, [foot - 900.0, mid], 2.0, 90.0, 15.0)),
        ("over the edge, looking down it", camera_at(&r, &dem, [top + 30.0, mid], 2.0, 270.0, -40.0)),
        ("89.9° on the low ground", camera_at(&r, &dem, [foot - 20.0, mid], grazing_m, 270.0, -0.1)),
        ("89.9° on the high ground", camera_at(&r, &dem, [top + 20.0, mid], grazing_m, 90.0, -0.1)),
        ("along the cliff", camera_at(&r, &dem, [foot - 40.0, 10.0], 50.0, 10.0, -5.0)),
    ];
    let mut ruled = 0;
    for (k, (what, camera)) in views.into_iter().enumerate() {
        let a = render_and_audit(&mut r, &dem, what, &camera, tol, 50);
        if k == 0 {
            assert!(a.expect_sky > 50, "{what}: the cliff hides the sky? ({a:?})");
        }
        assert!(
            a.worst_seed_gap_m <= 0.0,
            "{what}: a seed's base is {} m above the mesh",
            a.worst_seed_gap_m
        );
        let (records, counters) = r.read_seeds().unwrap().unwrap();
        let placing = r.exact_placing(&camera);
        let on_face = records.iter().filter(|s| {
            let x = placing.grid_m(DVec3::from(s.position_rel_m.map(f64::from))).x;
            x > foot && x < top
        });
        assert_eq!(on_face.count(), 0, "{what}: seeds on the cliff face");
        ruled += counters.rule;
    }
    assert!(ruled > 0, "the slope rule never culled a seed: the views missed the cliff");
}

#[test]
fn a_one_pixel_dem_builds_and_renders() {
    let tmp = TempDir::new("extremes-one-pixel");
    let dem =
        write_geotiff(&tmp.path().join("one.tif"), [1, 1], vec![250.0f32], CLIFF_GRID, 32633, Some(-9999.0));
    let (dataset, _) = build(&tmp.path().join("out"), &["--dem", dem.to_str().unwrap()]);
    assert_eq!(dataset.height.pyramid.size, [1, 1]);
    let mut r = renderer(dataset, 160, 90);
    let dem = Dem::load(&r.dataset);
    for (what, camera) in [
        ("straight down", camera_at(&r, &dem, [5.0, 5.0], 10.0, 0.0, -90.0)),
        ("from the side", camera_at(&r, &dem, [-8.0, -8.0], 6.0, 45.0, -35.0)),
    ] {
        render_and_audit(&mut r, &dem, what, &camera, Tolerance::flat(0.05, 1.0), 20);
    }
}
