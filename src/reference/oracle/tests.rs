use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::Instant;

use indicatif::ProgressBar;

use super::*;
use crate::classes::ClassTable;
use crate::dataset::{
    Crs, FORMAT_VERSION, HeightLayer, LayerSpec, Manifest, Pyramid, Reduce, Sampling, Staging, Window,
    write_layer,
};
use crate::earth::placing::EarthPlacing;
use crate::seeds::pcg;
use crate::synth::{SynthParams, synthesize};

fn temp_out(name: &str) -> PathBuf {
    let root = std::env::temp_dir().join(format!("terramp-oracle-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    root.join(name)
}

/// A dataset of `size`² heights `height(i, j)`, `spacing_m` apart, in tiles of 8 cells (so a
/// segment crosses several), without land cover.
fn dem(name: &str, size: u32, spacing_m: f64, height: impl Fn(u32, u32) -> f32 + Sync) -> Dataset {
    let staging = Staging::begin(&temp_out(name)).unwrap();
    let spec = LayerSpec {
        name: "height",
        pyramid: Pyramid::new([size; 2], 8, 1, Sampling::Vertex),
        mips: 1,
        reduce: Reduce::Decimate,
    };
    let source = |w: Window| {
        let rows = w.y0..w.y0 + w.height;
        Ok::<_, String>(
            rows.flat_map(|y| (w.x0..w.x0 + w.width).map(move |x| (x, y)))
                .map(|(x, y)| height(x, y))
                .collect(),
        )
    };
    write_layer(&staging.path("height.pack"), &spec, source, &ProgressBar::hidden()).unwrap();
    let manifest = Manifest {
        format_version: FORMAT_VERSION,
        name: "oracle test".into(),
        crs: Crs { definition: "LOCAL".into(), note: "test".into() },
        origin_m: [500_000.0, 4_000_000.0],
        height: HeightLayer {
            pack: "height.pack".into(),
            spacing_m,
            pyramid: spec.pyramid,
            min_m: -1000.0,
            max_m: 1000.0,
            step_m: None,
            filled_samples: 0,
            valid_mask_pack: None,
        },
        imagery: None,
        landcover: None,
        vegetation: None,
        earth: None,
    };
    Dataset::open(&staging.commit(&manifest).unwrap()).unwrap()
}

fn clears(dataset: &Dataset, eye: [f64; 3], target: [f64; 3]) -> bool {
    segment_clears_dem(dataset, DVec3::from(eye), DVec3::from(target)).unwrap()
}

/// A stream of numbers in [0, 1).
fn random(state: &mut u32) -> f64 {
    *state = pcg(*state);
    f64::from(*state) / 4_294_967_296.0
}

#[test]
fn the_window_reads_every_sample_and_the_drawn_ground() {
    let height = |i: u32, j: u32| (pcg(i * 131 + j) % 1000) as f32 * 0.1;
    let ds = dem("window", 29, 7.5, height);
    let dem = DemWindow::load(&ds, [0.0, 0.0], [210.0, 210.0]).unwrap();
    let mut state = 9;
    let mut checked = 0;
    for _ in 0..500 {
        let p = DVec2::new(random(&mut state) * 210.0, random(&mut state) * 210.0);
        let (ground_m, gradient) = dem.ground(p);
        let at = |x: f64, y: f64| ds.height_at(x, y, 0).unwrap();
        assert!((ground_m - at(p.x, p.y)).abs() < 1e-9, "{p}");
        // Where the surface has no kink (a cell edge or diagonal), the gradient is its derivative.
        let e = 1e-6;
        let (east, west) = ((at(p.x + e, p.y) - ground_m) / e, (ground_m - at(p.x - e, p.y)) / e);
        let (north, south) = ((at(p.x, p.y + e) - ground_m) / e, (ground_m - at(p.x, p.y - e)) / e);
        if (east - west).abs() < 1e-4 && (north - south).abs() < 1e-4 {
            assert!((gradient.x - east).abs() < 1e-4 && (gradient.y - north).abs() < 1e-4, "{p}: {gradient}");
            checked += 1;
        }
    }
    assert!(checked > 400, "{checked} gradients checked");
    // Each cell is two planes through three of its samples: at a cell's centre, the mean of the two
    // samples its diagonal joins (whichever it is, not the mean of all four, as a bilinear patch).
    let centre =
        |i: u32, j: u32| ds.height_at((f64::from(i) + 0.5) * 7.5, (f64::from(j) + 0.5) * 7.5, 0).unwrap();
    let h = |i: u32, j: u32| f64::from(height(i, j));
    for (i, j) in [(3, 4), (4, 4), (10, 17), (11, 17)] {
        let rising = 0.5 * (h(i, j) + h(i + 1, j + 1));
        let falling = 0.5 * (h(i + 1, j) + h(i, j + 1));
        let c = centre(i, j);
        assert!((c - rising).abs() < 1e-9 || (c - falling).abs() < 1e-9, "cell ({i}, {j}): {c}");
    }
}

#[test]
fn segments_over_a_flat_plane() {
    let ds = dem("flat", 17, 10.0, |_, _| 100.0);
    assert!(clears(&ds, [5.0, 5.0, 101.0], [150.0, 120.0, 105.0]));
    assert!(clears(&ds, [5.0, 5.0, 100.0], [150.0, 5.0, 100.0]), "touching is not passing below");
    assert!(!clears(&ds, [5.0, 5.0, 101.0], [150.0, 120.0, 99.0]), "dips below before its end");
    assert!(!clears(&ds, [5.0, 5.0, 99.0], [150.0, 120.0, 120.0]), "eye below the ground");
    assert!(clears(&ds, [-50.0, 5.0, 50.0], [-10.0, 150.0, 50.0]), "no terrain beyond the dataset");
    assert!(!clears(&ds, [-50.0, 80.0, 90.0], [100.0, 80.0, 110.0]), "enters the dataset below ground");
    assert!(clears(&ds, [80.0, 80.0, 150.0], [80.0, 80.0, 100.5]), "vertical, above");
    assert!(!clears(&ds, [80.0, 80.0, 150.0], [80.0, 80.0, 50.0]), "vertical, through");
    // The last 1e-6 of the segment is ignored: a target a hair under the ground.
    assert!(clears(&ds, [5.0, 5.0, 200.0], [150.0, 120.0, 100.0 - 1e-5]));
    assert!(!clears(&ds, [5.0, 5.0, 200.0], [150.0, 120.0, 100.0 - 1e-3]));
}

const RIDGE_M: f32 = 50.0;

/// Row 16 raised to `RIDGE_M` from column 4 to 20, flat 0 elsewhere.
fn ridge(i: u32, j: u32) -> f32 {
    if j == 16 && (4..=20).contains(&i) { RIDGE_M } else { 0.0 }
}

#[test]
fn a_ridge_between_samples_is_caught() {
    let s = 10.0;
    let ds = dem("ridge", 32, s, ridge);
    let h = f64::from(RIDGE_M);
    // Across the ridge between two of its samples.
    assert!(!clears(&ds, [55.0, 100.0, h - 5.0], [55.0, 220.0, h - 5.0]));
    assert!(clears(&ds, [55.0, 100.0, h + 0.5], [55.0, 220.0, h + 0.5]));
    // Past the ridge's end, across cell (20, 16) from its south-east corner to its north-west one:
    // every sample and every cell edge the segment passes is at 0, but the cell's rising diagonal
    // joins the ridge's last sample to the ground, and the segment crosses it half-way up, at h/2.
    assert!(crate::dataset::surface::diagonal_rises([20, 16]));
    let along = |z: f64| clears(&ds, [22.0 * s, 15.0 * s, z], [19.0 * s, 18.0 * s, z]);
    assert!(!along(h / 4.0));
    assert!(!along(h / 2.0 - 0.01));
    assert!(along(h / 2.0 + 0.01));
}

/// The least height above the drawn ground of `ridge` along the segment, sampled every 1e-4: each
/// cell is the two triangles of the terrain mesh's index buffer, here the plane through a
/// triangle's three samples (barycentric), the one holding the point.
fn brute_min_clearance(eye: DVec3, target: DVec3, s: f64, sag_m: f64) -> f64 {
    let size = 32u32;
    let extent = f64::from(size - 1) * s;
    let (indices, _) = crate::passes::terrain::frame::grid_indices(8);
    // Vertex k of the node grid (with its skirt ring) is (k % 11, k / 11); inner cell (a, b) of a
    // node is drawn by the two triangles whose vertices all lie in (1..=9)², least at (a + 1, b + 1).
    let inner: Vec<[[f64; 2]; 3]> = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]].map(|k| [f64::from(k % 11) - 1.0, f64::from(k / 11) - 1.0]))
        .filter(|t| t.iter().all(|p| p.iter().all(|&c| (0.0..=8.0).contains(&c))))
        .collect();
    let surface = |x: f64, y: f64| {
        if !(0.0..=extent).contains(&x) || !(0.0..=extent).contains(&y) {
            return None;
        }
        let (gx, gy) = (x / s, y / s);
        let (i, j) = ((gx.floor() as u32).min(size - 2), (gy.floor() as u32).min(size - 2));
        let node = [f64::from(i - i % 8), f64::from(j - j % 8)];
        let local = [f64::from(i % 8), f64::from(j % 8)];
        let mut best = (f64::NEG_INFINITY, 0.0);
        for t in inner
            .iter()
            .filter(|t| t.iter().fold([9.0f64; 2], |m, p| [m[0].min(p[0]), m[1].min(p[1])]) == local)
        {
            let [a, b, c] = t.map(|p| [p[0] + node[0], p[1] + node[1]]);
            let det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
            let wa = ((b[1] - c[1]) * (gx - c[0]) + (c[0] - b[0]) * (gy - c[1])) / det;
            let wb = ((c[1] - a[1]) * (gx - c[0]) + (a[0] - c[0]) * (gy - c[1])) / det;
            let w = [wa, wb, 1.0 - wa - wb];
            let h = [a, b, c].map(|p| f64::from(ridge(p[0] as u32, p[1] as u32)));
            let least = w.iter().copied().fold(f64::INFINITY, f64::min);
            if least > best.0 {
                best = (least, w[0] * h[0] + w[1] * h[1] + w[2] * h[2]);
            }
        }
        Some(best.1)
    };
    let t_end = 1.0 - SEGMENT_END_SKIP;
    (0..10_000).map(|k| f64::from(k) * 1e-4).chain([t_end]).fold(f64::INFINITY, |least, t| {
        let p = eye + (target - eye) * t;
        surface(p.x, p.y).map_or(least, |h| least.min(p.z - sag_m * t * (1.0 - t) - h))
    })
}

#[test]
fn the_exact_walk_agrees_with_brute_force_on_random_segments() {
    let s = 10.0;
    let ds = dem("ridge-random", 32, s, ridge);
    let dem = DemWindow::load(&ds, [0.0, 0.0], [310.0, 310.0]).unwrap();
    let (mut state, mut occluded, mut sag_occluded) = (3u32, 0, 0);
    for n in 0..1000 {
        let mut point = |z_lo: f64, z_hi: f64| {
            let (x, y) = (random(&mut state) * 390.0 - 40.0, random(&mut state) * 390.0 - 40.0);
            DVec3::new(x, y, z_lo + random(&mut state) * (z_hi - z_lo))
        };
        // Half the segments stay above the flat ground, so only the ridge can hide them.
        let (z_lo, z_hi) = if n % 2 == 0 { (0.5, 65.0) } else { (-5.0, 65.0) };
        let (eye, target) = (point(z_lo, z_hi), point(z_lo, z_hi));
        // Straight over the flat sheet, and sagging as on a small Earth (6 m at the middle: the
        // clearance's least can then lie inside a planar piece).
        for sag_m in [0.0, 24.0] {
            let exact = dem.min_clearance_m(eye, target, 1.0 - SEGMENT_END_SKIP, sag_m, false);
            let brute = brute_min_clearance(eye, target, s, sag_m);
            // Samples are points of the segment: none is below the exact least; and between two
            // samples the clearance changes by at most its steepest rate times the step.
            let d = target - eye;
            let rate = d.z.abs() + sag_m + f64::from(RIDGE_M) / s * 2f64.sqrt() * d.truncate().length();
            assert!(exact <= brute + 1e-9, "segment {n}, sag {sag_m}: exact {exact} above a sample {brute}");
            if brute.is_finite() {
                assert!(
                    brute - exact <= rate * 1e-4 + 1e-9,
                    "segment {n}, sag {sag_m}: exact {exact}, sampled {brute}"
                );
            }
            // Brute force could only disagree within a step's change of 0, or over the dataset for
            // less than a step: none of these segments is that close a call.
            let close = exact.abs() <= rate * 1e-4 || brute.is_infinite() != exact.is_infinite();
            assert_eq!(
                exact < 0.0,
                brute < 0.0,
                "segment {n}, sag {sag_m}: exact {exact}, sampled {brute} (close: {close})"
            );
            if sag_m == 0.0 {
                assert_eq!(exact < 0.0, !segment_clears_dem(&ds, eye, target).unwrap(), "segment {n}");
                occluded += usize::from(exact < 0.0);
            } else {
                sag_occluded += usize::from(exact < 0.0);
            }
        }
    }
    assert!((200..=800).contains(&occluded), "{occluded} of 1000 occluded: the test says little");
    assert!(sag_occluded > occluded, "sagging, {sag_occluded} occluded against {occluded} straight");
}

/// Most the oracle's sagging segment may stray from the exact one over 4 km, in height and
/// across its track, metres (both compared where the exact segment passes over the grid).
const MAX_SAG_HEIGHT_MISS_M: f64 = 0.002;
/// See `MAX_SAG_HEIGHT_MISS_M`.
const MAX_SAG_TRACK_MISS_M: f64 = 0.005;

/// The sag the oracle gives a straight segment on the Earth (second order: t (1 − t) (L² + 2 Δz²)
/// / 2R, its ground track the grid's straight line) against the exact one: points of the segment in space
/// taken back to the grid by the exact inverse, from 500 m above nc's State Plane to ground
/// points up to 4 km away.
#[test]
fn a_straight_segment_sags_over_the_earth_as_the_oracle_says() {
    let earth = crate::earth::test_frames::nc();
    let eye = DVec3::new(40_000.0, 30_000.0, 500.0);
    let placing = EarthPlacing::new(Some(&earth), [600_000.0, 180_000.0], true).exact(eye);
    let sag_per_m2 = frame::sag_per_m2(&placing);
    // 1 / 2R, R between the meridian's and the prime vertical's radii at 36° N.
    assert!((sag_per_m2 * 2.0 * 6.37e6 - 1.0).abs() < 0.005, "{sag_per_m2}");
    let (mut worst_height_m, mut worst_track_m) = (0.0f64, 0.0f64);
    for k in 0..16 {
        let angle = f64::from(k) * std::f64::consts::TAU / 16.0;
        let target =
            eye + DVec3::new(4_000.0 * angle.cos(), 4_000.0 * angle.sin(), -500.0 + 37.0 * f64::from(k));
        let (rel, length_sq) = (placing.position_rel_m(target), (target - eye).truncate().length_squared());
        for i in 1..16 {
            let t = f64::from(i) / 16.0;
            // Where the point lies on the grid, and at what parameter the oracle's track passes it.
            let on_grid = placing.grid_m(rel * t);
            let across = (target - eye).truncate();
            let t = (on_grid - eye).truncate().dot(across) / length_sq;
            let rise = target - eye;
            let sag_m = sag_per_m2 * (length_sq + 2.0 * rise.z * rise.z);
            let said = eye + rise * t - DVec3::Z * (sag_m * t * (1.0 - t));
            worst_height_m = worst_height_m.max((on_grid.z - said.z).abs());
            worst_track_m = worst_track_m.max((on_grid - said).truncate().length());
        }
    }
    println!(
        "at 4 km: heights {:.2} mm, track {:.2} mm off the exact segment",
        worst_height_m * 1e3,
        worst_track_m * 1e3
    );
    assert!(worst_height_m < MAX_SAG_HEIGHT_MISS_M, "the sag misses by {worst_height_m} m");
    assert!(worst_track_m < MAX_SAG_TRACK_MISS_M, "the track misses by {worst_track_m} m");
}

/// The synthetic dataset of `size`² samples (10 m), built once per test process.
fn synthetic(size: u32) -> Dataset {
    static BUILT: OnceLock<std::sync::Mutex<Vec<(u32, PathBuf)>>> = OnceLock::new();
    let mut built = BUILT.get_or_init(Default::default).lock().unwrap();
    let dir = match built.iter().find(|(n, _)| *n == size) {
        Some((_, dir)) => dir.clone(),
        None => {
            let params =
                SynthParams { size, seed: 3, origin_m: [630_000.0, 215_000.0], ..Default::default() };
            let dir = synthesize(&temp_out(&format!("synth-{size}")), &params, false).unwrap();
            built.push((size, dir.clone()));
            dir
        }
    };
    Dataset::open(&dir).unwrap()
}

/// Runs `judge` with the oracle's inputs on `dataset` from grid point (x, y), `above_m` over the
/// ground, looking along `yaw_deg` and `pitch_deg`.
fn with_inputs<R>(
    dataset: &Dataset,
    pose: [f64; 5],
    viewport_px: [u32; 2],
    judge: impl FnOnce(&OracleInputs) -> R,
) -> R {
    let settings = Settings::default();
    let landcover = dataset.manifest.landcover.as_ref().unwrap();
    let table = ClassTable::load(&landcover.scheme).unwrap();
    let spp = settings.seeds.seeds_per_pattern;
    let tables = SeedTables::new(&table, &landcover.coding, settings.tlm.cell_m, spp, 1.0).unwrap();
    let patterns = SeedPatterns::generate(settings.tlm.corner_colours(), spp, settings.tlm.seed);
    let [x, y, above_m, yaw_deg, pitch_deg] = pose;
    let origin = dataset.manifest.origin_m;
    let z = dataset.height_at(x, y, 0).unwrap() + above_m;
    let position_m = DVec3::new(origin[0] + x, origin[1] + y, z);
    let camera = Camera { position_m, yaw_deg, pitch_deg, roll_deg: 0.0, fov_deg: 60.0, near_m: 0.1 };
    judge(&OracleInputs {
        dataset,
        settings: &settings,
        tables: &tables,
        patterns: &patterns,
        camera: &camera,
        viewport_px,
    })
}

/// The visible seeds (pass 3's rule, exactly) of the view `with_inputs` describes.
fn run(dataset: &Dataset, pose: [f64; 5], viewport_px: [u32; 2]) -> (Vec<OracleSeed>, OracleCounts) {
    with_inputs(dataset, pose, viewport_px, |inputs| visible_seeds(inputs).unwrap())
}

#[test]
fn fates_seed_by_seed_agree_with_the_judge() {
    let ds = synthetic(160);
    // Low over the ground, looking level: some seeds beyond reach, some behind the hills.
    let pose = [200.0, 200.0, 3.0, 45.0, 0.0];
    with_inputs(&ds, pose, [400, 250], |inputs| {
        // Every seed in view out to beyond the draw reaches, occluded or not, judged again by pass
        // 3's rule: the visible ones are exactly the judge's, the others beyond reach or hidden.
        let wide = Culls { reach_m: Some(5000.0), occlusion: false, frustum: true };
        let (all, _) = judge_seeds(inputs, wide).unwrap();
        let (visible, counts) = visible_seeds(inputs).unwrap();
        let fates = fates_of(inputs, Culls::SELECTION, &all).unwrap();
        let kept: Vec<OracleSeed> =
            fates.iter().filter_map(|f| if let Fate::Visible(s) = f { Some(*s) } else { None }).collect();
        assert_eq!(kept, visible);
        let count = |want: fn(&Fate) -> bool| fates.iter().filter(|f| want(f)).count() as u64;
        assert_eq!(count(|f| matches!(f, Fate::Occlusion)), counts.occlusion);
        assert!(count(|f| matches!(f, Fate::Distance)) > 0 && counts.occlusion > 0, "{counts:?}");
        assert_eq!(count(|f| matches!(f, Fate::Class | Fate::Rule | Fate::Frustum)), 0);
        // And under the judge's own culls, every seed it kept stays.
        let again = fates_of(inputs, wide, &all).unwrap();
        assert!(again.iter().zip(&all).all(|(f, s)| *f == Fate::Visible(*s)));
    });
}

#[test]
fn the_oracle_is_deterministic_and_accounts_for_every_seed() {
    let ds = synthetic(160);
    let pose = [795.0, 795.0, 40.0, 30.0, -8.0];
    let (seeds, counts) = run(&ds, pose, [400, 250]);
    assert_eq!(run(&ds, pose, [400, 250]), (seeds.clone(), counts));
    let c = counts;
    assert_eq!(c.class + c.rule + c.distance + c.frustum + c.occlusion + c.visible, c.candidates);
    assert_eq!(c.visible, seeds.len() as u64);
    assert!(c.visible > 0 && c.frustum > 0, "{c:?}");
    assert!(seeds.windows(2).all(|w| (w[0].address, w[0].rank) < (w[1].address, w[1].rank)));
    let origin = ds.manifest.origin_m;
    let z = ds.height_at(pose[0], pose[1], 0).unwrap() + pose[2];
    let eye = DVec3::new(pose[0], pose[1], z);
    let sink = Settings::default().seeds.sink_fraction;
    for seed in seeds.iter().step_by(97) {
        assert!(seed.lod < crate::gpu::layout::SEED_LODS);
        let [x, y] = seed.position_grid_m;
        assert!((seed.ground_m - ds.height_at(x, y, 0).unwrap()).abs() < 1e-9);
        let summit = DVec3::new(x, y, seed.ground_m + (1.0 - sink) * seed.height_m);
        assert!(segment_clears_dem(&ds, eye, summit).unwrap(), "{seed:?} (origin {origin:?})");
    }
    // From under the ground nothing is visible.
    let (seeds, counts) = run(&ds, [795.0, 795.0, -1.0, 30.0, -8.0], [400, 250]);
    assert!(seeds.is_empty() && counts.visible == 0 && counts.occlusion > 0, "{counts:?}");
}

/// The oracle's cost on a typical view: `cargo test --lib oracle_runtime -- --ignored --nocapture`.
#[test]
#[ignore = "measurement, no check: prints the oracle's time on two views of a 1024² dataset"]
fn oracle_runtime_on_a_typical_view() {
    let ds = synthetic(1024);
    for pose in [[5115.0, 5115.0, 30.0, 30.0, -5.0], [3000.0, 4000.0, 150.0, 120.0, -12.0]] {
        let start = Instant::now();
        let (seeds, counts) = run(&ds, pose, [1280, 720]);
        eprintln!("pose {pose:?}: {} visible in {:.2?}: {counts:?}", seeds.len(), start.elapsed());
    }
}
