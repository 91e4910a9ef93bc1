//! Texcells at the extremes, over a synthetic forest built for it (nc's forest class everywhere,
//! no seeds drawn, so that the texcells alone are seen): a grazing view and a camera inside the
//! canopy leave no gaps and no broken pixels, with silhouette texcells and without.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::Path;

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::passes::texcells::frame::Band;
use terramp_testkit::{TempDir, shared_data};

use gdal::GeoTransform;
use support::texcells::{SIZE, changed, render_from, samples};
use support::{FOREST, build, ground_under_pixels, write_geotiff};

/// The `texcells.silhouette_deg` the tests draw silhouettes with.
const SILHOUETTE_DEG: f64 = 3.0;

/// A dataset of `size` 30 m cells whose ground, metres, is `height_m(x_m)` (x east from the west
/// edge), forest everywhere; and the forest sample's slab height, metres.
fn forest_world(
    dir: &TempDir,
    size: [usize; 2],
    height_m: &dyn Fn(f64) -> f32,
) -> (Dataset, std::path::PathBuf, f64) {
    let grid: GeoTransform = [500_000.0, 30.0, 0.0, 5_000_000.0, 0.0, -30.0];
    let n = size[0] * size[1];
    let heights: Vec<f32> = (0..n).map(|i| height_m(30.0 * (i % size[0]) as f64 + 15.0)).collect();
    let dem = write_geotiff(&dir.path().join("dem.tif"), size, heights, grid, 32633, None);
    let cover =
        write_geotiff(&dir.path().join("forest.tif"), size, vec![FOREST; n], grid, 32633, Some(255.0));
    let args = ["--dem", dem.to_str().unwrap(), "--landcover", cover.to_str().unwrap(), "--classes", "nc"];
    let path = dir.path().join("out");
    let (dataset, _) = build(&path, &args);
    let canopy_m = f64::from(terramp::texcell::load(samples(), FOREST).unwrap().unwrap().height_m);
    (dataset, path, canopy_m)
}

/// The extremes of DESIGN.md for texcells, over a flat forest (a 12 km square at 30 m, nc's forest
/// class everywhere, no seeds drawn so that the texcells alone are seen):
/// - **grazing**: the eye 8.7 m above the canopy's top, pitched 0.1° down, so the central ray
///   meets the canopy at 89.9° incidence 5 km out; through a 4° lens, so the band is rows tall,
///   and texcells to 12 km. Every pixel whose ray crosses the canopy's upper half (the crowns)
///   inside the texcell band crosses every slice there: at least 90 % of them must show forest
///   (the oblique opacity correction keeps edge-on slices dense: no see-through gaps);
/// - **inside the canopy**: the eye 12 m up, level (slices above it seen from below).
///
/// Both are drawn with silhouette texcells (the grazing view's kind) and without (regular slices
/// alone). None gives a pixel black or white where the ground was not (a NaN or an infinity in
/// the slices' opacity or the silhouettes' march).
#[test]
fn texcells_at_grazing_incidence_and_inside_the_canopy_leave_no_gaps() {
    if shared_data().is_none() {
        return;
    }
    let dir = TempDir::new("texcells-extremes");
    let (dataset, path, canopy_m) = forest_world(&dir, [400, 400], &|_| 100.0);
    let [_, north_m] = dataset.manifest.extent_m();
    let grazing = [canopy_m + 5000.0 * 0.1f64.to_radians().tan(), -0.1, 4.0];
    const FAR_M: f64 = 12000.0;
    let views = [("grazing (89.9°)", grazing), ("inside the canopy", [12.0, 0.0, 60.0])];
    for ((what, [above_m, pitch, fov_deg]), silhouette_deg) in
        views.into_iter().flat_map(|v| [(v, 0.0), (v, SILHOUETTE_DEG)])
    {
        let band = {
            let mut s = Settings::preset("balanced").unwrap();
            s.texcells.reach_m = FAR_M;
            Band::of(&s)
        };
        let camera_of = |r: &Renderer| Camera {
            fov_deg,
            ..terramp_testkit::camera::over(r, [300.0, north_m / 2.0], above_m, 90.0, pitch)
        };
        // On the flat sheet: the view's geometry (a flat forest, the crossings by similar
        // triangles) is the sheet's; on the Earth the canopy falls 2 m below the eye's
        // horizontal 5 km out. The bend is tested in tests/earth_terrain.rs.
        let none = |s: &mut Settings| s.render.curved_earth = false;
        let (_, bare, depth, _, camera) =
            render_from(Dataset::open(&path).unwrap(), samples(), 0.0, &none, &camera_of);
        let kind = |s: &mut Settings| {
            none(s);
            s.texcells.silhouette_deg = silhouette_deg;
        };
        let (_, forest, _, report, _) =
            render_from(Dataset::open(&path).unwrap(), samples(), FAR_M, &kind, &camera_of);
        let ground = ground_under_pixels(&dataset, &camera, SIZE, &depth, false);
        // Rays through the crowns (the canopy's upper half) within the band's inside.
        let inside =
            |d: f64| d > band.fade_in_m + band.fade_in_width_m && d < band.reach_m - band.fade_out_width_m;
        let through: Vec<usize> = (0..ground.len())
            .filter(|&i| {
                ground[i].is_some_and(|g| {
                    inside(g.distance_m * (1.0 - 0.5 * canopy_m / above_m))
                        && inside(g.distance_m * (1.0 - canopy_m / above_m))
                })
            })
            .collect();
        let covered = through.iter().filter(|&&i| changed(&bare, &forest, i)).count();
        let extreme = |p: &[u8]| p[..3].iter().all(|&c| c < 4) || p[..3].iter().all(|&c| c > 251);
        let broken = (0..(SIZE[0] * SIZE[1]) as usize)
            .filter(|&i| {
                extreme(&forest.as_raw()[4 * i..4 * i + 4]) && !extreme(&bare.as_raw()[4 * i..4 * i + 4])
            })
            .count();
        let what = format!("{what}, silhouettes below {silhouette_deg}°");
        println!(
            "{what}: {} slices, {} silhouettes; {covered} of {} pixels seen through the whole canopy in the band show forest; {broken} black or white",
            report.texcells.slices,
            report.texcells.silhouettes,
            through.len()
        );
        let shots = Path::new(env!("CARGO_TARGET_TMPDIR"));
        let name = format!("texcells_flat_{}_{silhouette_deg}.png", what.split(' ').next().unwrap());
        forest.save(shots.join(name)).unwrap();
        assert_eq!(broken, 0, "{what}: pixels black or white from the texcells");
        if what.starts_with("grazing") {
            assert!(
                through.len() > 500,
                "{what}: only {} pixels see the canopy in the band: a weak test",
                through.len()
            );
            // Nine in ten: on lavapipe all of them show forest (822 of 822, docs/texcells.md); the
            // tenth is room for another rasteriser's coverage of the slices' alpha-tested edges.
            assert!(
                covered * 10 >= through.len() * 9,
                "{what}: gaps: {covered} of {} pixels show forest",
                through.len()
            );
        }
    }
}

/// A forested ridge seen edge-on: flat ground at 100 m with a ridge 150 m high (a Gaussian across,
/// σ 120 m) running north–south 5 km east of the eye, which stands 10 m above the canopy on its
/// crest, looking east through a 4° lens, so that the crest's forest is the skyline, mid-band.
/// Per column, the skyline is the highest pixel texcells changed from the bare ridge: with regular
/// slices and with silhouette texcells, every column's skyline is forest (no gap where the view
/// grazes the crest). Its relief (the mean distance of the skyline from its own 17-column moving
/// average, pixels) is printed: 0.21 px with regular slices, 0.29 with silhouettes, both flat
/// (`texcells.silhouette_deg` stays off until silhouettes are judged against the truth).
#[test]
fn a_forested_skyline_seen_edge_on_has_no_gaps() {
    if shared_data().is_none() {
        return;
    }
    let dir = TempDir::new("texcells-ridge");
    const CREST_X_M: f64 = 5300.0;
    let ridge = |x: f64| (100.0 + 150.0 * (-0.5 * ((x - CREST_X_M) / 120.0).powi(2)).exp()) as f32;
    let (dataset, path, canopy_m) = forest_world(&dir, [400, 400], &ridge);
    let [_, north_m] = dataset.manifest.extent_m();
    let eye_m = 250.0 + canopy_m + 10.0;
    let camera_of = |r: &Renderer| Camera {
        fov_deg: 4.0,
        ..terramp_testkit::camera::at_grid(
            r,
            glam::DVec3::new(300.0, north_m / 2.0, eye_m),
            90.0,
            -(10.0 + 0.5 * canopy_m).atan2(CREST_X_M - 300.0).to_degrees(),
        )
    };
    let none = |_: &mut Settings| {};
    let (_, bare, ..) = render_from(Dataset::open(&path).unwrap(), samples(), 0.0, &none, &camera_of);
    let [w, h] = SIZE.map(|v| v as usize);
    for silhouette_deg in [0.0, SILHOUETTE_DEG] {
        let kind = |s: &mut Settings| {
            none(s);
            s.texcells.silhouette_deg = silhouette_deg;
        };
        let (_, forest, _, report, _) =
            render_from(Dataset::open(&path).unwrap(), samples(), 12_000.0, &kind, &camera_of);
        let skyline: Vec<f64> = (0..w)
            .map(|x| (0..h).find(|&y| changed(&bare, &forest, y * w + x)).unwrap_or(h) as f64)
            .collect();
        let missing = skyline.iter().filter(|&&y| y == h as f64).count();
        const HALF: usize = 8;
        let relief = (HALF..w - HALF)
            .map(|x| {
                let mean = skyline[x - HALF..=x + HALF].iter().sum::<f64>() / (2 * HALF + 1) as f64;
                (skyline[x] - mean).abs()
            })
            .sum::<f64>()
            / (w - 2 * HALF) as f64;
        println!(
            "silhouettes below {silhouette_deg}°: {} slices, {} silhouettes; skyline relief {relief:.2} px, mean row {:.1}, {missing} columns without forest",
            report.texcells.slices,
            report.texcells.silhouettes,
            skyline.iter().sum::<f64>() / w as f64
        );
        let shot =
            Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("texcells_ridge_{silhouette_deg}.png"));
        forest.save(shot).unwrap();
        assert_eq!(
            missing, 0,
            "silhouettes below {silhouette_deg}°: columns where the ridge shows no forest"
        );
        assert!(
            (silhouette_deg > 0.0) == (report.texcells.silhouettes > 0),
            "{} silhouettes drawn with silhouette_deg {silhouette_deg}",
            report.texcells.silhouettes
        );
    }
}
