//! The ground truth (`terramp::truth`) on a small synthetic dataset with the shared models baked:
//! - its samples equal an independent CPU rasterisation (`truth/raster.rs`: its own pinhole
//!   camera, the level-0 DEM triangulated as the finest mesh is, the models' meshes with their
//!   alpha test) of the same scene, within the tolerances stated at each assertion;
//! - its any-part visibility on hand-built scenes: a tree fully hidden behind a ridge has no
//!   sample; raised until it shows, it first shows a single pixel's worth of samples; a tree just
//!   outside the view (its trunk and summit off screen) whose crown pokes in is visible;
//! - a truth grown from the land cover is written whole and reads back.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

#[path = "truth/raster.rs"]
mod raster;

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use terramp::camera::Camera;
use terramp::classes::SpeciesKind;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::impostor::{AlphaMode, Impostor};
use terramp::reference::oracle::{OracleSeed, segment_clears_dem};
use terramp::seeds::{pcg, seed_hash};
use terramp::truth::{Truth, TruthOptions, TruthRenderer, draw_truth, files, render_truth, truth_settings};
use terramp_testkit::data::target_tmp_dir;
use terramp_testkit::{camera, gpu, small_settings, synth_dataset};

use raster::{Corner, Pinhole, Raster};

/// Samples per pixel along each axis, and the image in pixels.
const SUPERSAMPLE: u32 = 4;
const IMAGE_PX: [u32; 2] = [48, 27];
/// The synthetic dataset: 128² samples 10 m apart.
const DATASET: (u32, u64) = (128, 7);
/// A larger one, with hills: ridges with valleys behind them, seen at twice the resolution.
const RIDGE_DATASET: (u32, u64) = (512, 1);
const RIDGE_IMAGE_PX: [u32; 2] = [96, 54];
/// The tree hidden behind the ridge, metres.
const TREE_M: f64 = 15.0;
/// Least share of samples on which the truth and the CPU agree on what they show: only samples on
/// an edge may differ (the GPU's coverage rule and its filtered, mipmapped alpha against the
/// CPU's nearest texel), 0.5 % of all.
const MIN_SAMPLES_AGREEING: f64 = 0.995;
/// Least intersection over union of each seed's samples, truth against CPU: a seed covers the same
/// samples bar its outline, and the smallest (a 1.2 m rock 9 m away) has few samples inside it.
const MIN_SEED_IOU: f64 = 0.85;
/// Where both show the terrain, its depths agree to f32 rounding of camera-relative positions.
const DEPTH_TOLERANCE_REL: f64 = 1e-4;
/// Least share of those samples within it: a sample on a triangle's edge may take the other's.
const MIN_DEPTHS_AGREEING: f64 = 0.995;

fn impostors() -> Option<&'static Path> {
    terramp_testkit::nc_impostors()
}

/// A truth renderer over a synthetic dataset (size, seed), settled at `camera`'s pose `[fx, fy, above, yaw,
/// pitch]` (fractions of the extent, metres above the ground, degrees).
fn settled((size, seed): (u32, u64), image_px: [u32; 2], pose: [f64; 5]) -> (Renderer, Camera) {
    let dir = synth_dataset(size, seed);
    let dataset = Dataset::open(&dir).unwrap();
    let settings = truth_settings(&small_settings(image_px[0], image_px[1]), &dataset, SUPERSAMPLE);
    let mut r = Renderer::new(gpu(), dataset, settings).unwrap();
    r.pin_everything().unwrap();
    let [fx, fy, above, yaw, pitch] = pose;
    let camera = camera::over_fraction(&r, [fx, fy], above, yaw, pitch);
    r.render_resolved(&camera).unwrap();
    (r, camera)
}

fn eye_grid(r: &Renderer, camera: &Camera) -> DVec3 {
    let o = r.dataset.manifest.origin_m;
    camera.position_m - DVec3::new(o[0], o[1], 0.0)
}

/// The first species of `kind` in the renderer's class table.
fn species_of(r: &Renderer, kind: SpeciesKind) -> u32 {
    r.class_table().unwrap().species.iter().position(|s| s.kind == kind).unwrap() as u32
}

/// A hand-built seed standing at grid `xy` on `ground_m`, `height_m` tall.
fn seed(species: u32, rank: u32, xy: DVec2, ground_m: f64, height_m: f64) -> OracleSeed {
    OracleSeed { address: [1, 2], rank, species, position_grid_m: xy.to_array(), ground_m, height_m, lod: 0 }
}

fn truth_of(r: &Renderer, camera: &Camera, seeds: Vec<OracleSeed>) -> Truth {
    draw_truth(r, camera, seeds, impostors().unwrap(), SUPERSAMPLE).unwrap()
}

/// What the CPU rasterises otherwise than the truth draws, for the controls.
#[derive(Clone, Copy, Default)]
struct Wrong {
    /// Every second sample of the DEM in each direction: a terrain one level too coarse.
    coarse_terrain: bool,
    /// Every seed moved this far aside (metres, grid x).
    seeds_aside_m: f64,
}

/// The CPU rasterisation of the truth's scene: the level-0 DEM, two triangles per cell with the
/// finest mesh's alternating diagonals (south-west–north-east where column + row is even), and
/// each seed's mesh placed, scaled and turned as pass 4 does (or, for a control, `wrong`).
fn cpu_raster(r: &Renderer, camera: &Camera, truth: &Truth, wrong: Wrong) -> Raster {
    let size = truth.size_px.map(|n| n * SUPERSAMPLE);
    let view = Pinhole::new(camera, size);
    let mut raster = Raster::new(size);
    let eye = eye_grid(r, camera);
    let d = &r.dataset;
    let spacing = d.manifest.height.spacing_m;
    let [nx, ny] = d.height.pyramid.size;
    let corner = |i: u32, j: u32| {
        let h = d.height_sample(0, i, j).unwrap();
        Corner { rel_m: DVec3::new(f64::from(i) * spacing, f64::from(j) * spacing, h) - eye, uv: DVec2::ZERO }
    };
    let step = if wrong.coarse_terrain { 2 } else { 1 };
    for j in (0..ny - 1).step_by(step as usize) {
        for i in (0..nx - 1).step_by(step as usize) {
            let (i1, j1) = ((i + step).min(nx - 1), (j + step).min(ny - 1));
            let (sw, se, nw, ne) = (corner(i, j), corner(i1, j), corner(i, j1), corner(i1, j1));
            let pair =
                if (i + j) % 2 == 0 { [[sw, se, ne], [sw, ne, nw]] } else { [[sw, se, nw], [se, ne, nw]] };
            for t in pair {
                raster.triangle(&view, t, 0, &|_| true);
            }
        }
    }
    let table = r.class_table().unwrap();
    let settings = &r.settings;
    for (k, s) in truth.seeds.iter().enumerate() {
        let model = &table.species[s.species as usize].model;
        let impostor = terramp::impostor::load(impostors().unwrap(), model).unwrap();
        let mesh = &impostor.mesh;
        let top = mesh.vertices.iter().map(|v| f64::from(v.position_model_m[1])).fold(0.0, f64::max);
        let scale = s.height_m / top;
        let address = s.address.map(|a| a as i32);
        let angle = f64::from(pcg(seed_hash(address, s.rank, settings.tlm.seed)) & 0xffff)
            * std::f64::consts::TAU
            / 65536.0;
        let (sin, cos) = angle.sin_cos();
        let [x, y] = s.position_grid_m;
        let x = x + wrong.seeds_aside_m;
        let anchor = DVec3::new(x, y, s.ground_m - settings.seeds.sink_fraction * s.height_m) - eye;
        let place = |p: [f32; 3]| {
            // Model space is +Y up; the world is z up, the model's −z north, then turned.
            let w = DVec3::new(f64::from(p[0]), -f64::from(p[2]), f64::from(p[1])) * scale;
            anchor + DVec3::new(cos * w.x - sin * w.y, sin * w.x + cos * w.y, w.z)
        };
        for submesh in &mesh.submeshes {
            let material = &mesh.materials[submesh.material as usize];
            let keep = alpha_test(&impostor, submesh.material as usize);
            let first = submesh.first_index as usize;
            for t in mesh.indices[first..first + submesh.index_count as usize].chunks_exact(3) {
                let corners = [0, 1, 2].map(|c| {
                    let v = &mesh.vertices[t[c] as usize];
                    Corner {
                        rel_m: place(v.position_model_m),
                        uv: DVec2::new(v.uv[0].into(), v.uv[1].into()),
                    }
                });
                raster.triangle(&view, corners, k as u32 + 1, &|uv| {
                    material.alpha_mode == AlphaMode::Opaque || keep(uv)
                });
            }
        }
    }
    raster
}

/// Material `m`'s alpha test at full resolution, nearest texel, repeating.
fn alpha_test(impostor: &Impostor, m: usize) -> impl Fn(DVec2) -> bool + '_ {
    let material = &impostor.mesh.materials[m];
    move |uv: DVec2| {
        let Some(texture) = &material.texture else {
            return material.base_color_factor[3] >= material.alpha_cutoff;
        };
        let [w, h] = texture.size;
        let texel = |v: f64, n: u32| ((v - v.floor()) * f64::from(n)).floor().min(f64::from(n - 1)) as u32;
        let (x, y) = (texel(uv.x, w), texel(uv.y, h));
        let alpha = f32::from(texture.levels[0][4 * (y * w + x) as usize + 3]) / 255.0;
        alpha * material.base_color_factor[3] >= material.alpha_cutoff
    }
}

#[test]
fn the_truth_equals_an_independent_cpu_rasterisation_of_a_small_scene() {
    if impostors().is_none() {
        return;
    }
    let (r, camera) = settled(DATASET, IMAGE_PX, [0.35, 0.35, 3.0, 45.0, -8.0]);
    let eye = eye_grid(&r, &camera);
    let forward = DVec2::new(45f64.to_radians().sin(), 45f64.to_radians().cos());
    let side = forward.perp();
    let (tree, rock) = (species_of(&r, SpeciesKind::Tree), species_of(&r, SpeciesKind::Rock));
    let stand = |along: f64, across: f64, species, rank, height_m| {
        let xy = eye.truncate() + forward * along + side * across;
        seed(species, rank, xy, r.dataset.height_at(xy.x, xy.y, 0).unwrap(), height_m)
    };
    let seeds = vec![
        stand(18.0, -4.0, tree, 0, 7.0),
        stand(30.0, 5.0, tree, 1, 9.0),
        stand(45.0, -12.0, tree, 2, 8.0),
        stand(9.0, 2.0, rock, 3, 1.2),
    ];
    let truth = truth_of(&r, &camera, seeds);
    let cpu = cpu_raster(&r, &camera, &truth, Wrong::default());
    let n = truth.seed_ids.len();
    assert_eq!(n, cpu.ids.len());
    let share = samples_agreeing(&truth, &cpu);
    println!("samples agreeing on what they show: {:.3} %", 100.0 * share);
    assert!(share >= MIN_SAMPLES_AGREEING, "{share} of the samples agree");
    let overlaps = seed_overlaps(&truth, &cpu);
    println!("seeds' overlap (intersection over union): {overlaps:.3?}");
    assert!(overlaps.iter().all(|&o| o >= MIN_SEED_IOU), "{overlaps:?}");
    let (close, terrain) = depths_agreeing(&truth, &cpu);
    println!("terrain samples with depth within {DEPTH_TOLERANCE_REL} (relative): {close} / {terrain}");
    // Real: a quarter of the samples are the terrain's, so the share below is not of a handful.
    assert!(terrain > n / 4, "only {terrain} of {n} samples show the terrain to both");
    assert!(close as f64 >= MIN_DEPTHS_AGREEING * terrain as f64);

    // Controls: a terrain one level too coarse fails the depths, seeds a metre aside the overlap.
    let coarse = cpu_raster(&r, &camera, &truth, Wrong { coarse_terrain: true, ..Wrong::default() });
    let (close, terrain) = depths_agreeing(&truth, &coarse);
    println!("control, every second sample: {close} / {terrain} terrain depths agree");
    assert!(terrain > n / 4 && (close as f64) < MIN_DEPTHS_AGREEING * terrain as f64);
    let aside = cpu_raster(&r, &camera, &truth, Wrong { seeds_aside_m: 1.0, ..Wrong::default() });
    let overlaps = seed_overlaps(&truth, &aside);
    println!("control, seeds 1 m aside: overlaps {overlaps:.3?}");
    assert!(overlaps.iter().all(|&o| o < MIN_SEED_IOU), "{overlaps:?}");
}

/// Share of samples on which truth and CPU show the same: the sky, the terrain, or seed k.
fn samples_agreeing(truth: &Truth, cpu: &Raster) -> f64 {
    let class = |id: u32, depth: f64| if id > 0 { id + 1 } else { u32::from(depth > 0.0) };
    let n = truth.seed_ids.len();
    let agree = (0..n)
        .filter(|&i| class(truth.seed_ids[i], truth.depth[i].into()) == class(cpu.ids[i], cpu.depth[i]))
        .count();
    agree as f64 / n as f64
}

/// Per seed, the intersection over union of the samples it covers in the truth and on the CPU;
/// a seed the truth does not show at all is 0.
fn seed_overlaps(truth: &Truth, cpu: &Raster) -> Vec<f64> {
    let n = truth.seed_ids.len();
    (1..=truth.seeds.len() as u32)
        .map(|k| {
            let gpu = (0..n).filter(|&i| truth.seed_ids[i] == k).count();
            let on_cpu = (0..n).filter(|&i| cpu.ids[i] == k).count();
            let both = (0..n).filter(|&i| truth.seed_ids[i] == k && cpu.ids[i] == k).count();
            if gpu == 0 { 0.0 } else { both as f64 / (gpu + on_cpu - both) as f64 }
        })
        .collect()
}

/// Of the samples both show as terrain, how many have their depths within the tolerance, and how
/// many there are.
fn depths_agreeing(truth: &Truth, cpu: &Raster) -> (usize, usize) {
    let terrain: Vec<usize> = (0..truth.seed_ids.len())
        .filter(|&i| truth.seed_ids[i] == 0 && cpu.ids[i] == 0 && cpu.depth[i] > 0.0 && truth.depth[i] > 0.0)
        .collect();
    let close = terrain
        .iter()
        .filter(|&&i| (f64::from(truth.depth[i]) - cpu.depth[i]).abs() <= DEPTH_TOLERANCE_REL * cpu.depth[i])
        .count();
    (close, terrain.len())
}

/// A view with a ridge ahead and lower ground behind it: the camera's grid position (2 m above
/// the ground), its heading, the slope of the sight line over the ridge and the tree's distance
/// behind it. Searched over a grid of positions and headings.
fn ridge_view(d: &Dataset) -> (DVec2, f64, f64, f64) {
    let [w, h] = d.manifest.extent_m();
    let ground = |p: DVec2| d.height_at(p.x, p.y, 0).unwrap();
    let inside = |p: DVec2| p.x > 20.0 && p.y > 20.0 && p.x < w - 20.0 && p.y < h - 20.0;
    for fy in (2..=16).map(|v| f64::from(v) / 20.0) {
        for fx in (2..=16).map(|v| f64::from(v) / 20.0) {
            for yaw in (0..24).map(|k| f64::from(k) * 15.0) {
                let eye = DVec2::new(fx * w, fy * h);
                let eye_z = ground(eye) + 2.0;
                let dir = DVec2::new(yaw.to_radians().sin(), yaw.to_radians().cos());
                let slope = |t: f64| (ground(eye + dir * t) - eye_z) / t;
                let steps = (4..=120).map(|k| f64::from(k) * 2.5).take_while(|&t| inside(eye + dir * t));
                let Some((t_ridge, s_ridge)) =
                    steps.map(|t| (t, slope(t))).max_by(|a, b| a.1.total_cmp(&b.1))
                else {
                    continue;
                };
                let behind = (1..=8).map(|k| t_ridge + f64::from(k) * 20.0);
                let margin = |t: f64| eye_z + s_ridge * t - ground(eye + dir * t);
                let t_tree = behind
                    .filter(|&t| inside(eye + dir * t))
                    .max_by(|&a, &b| margin(a).total_cmp(&margin(b)))
                    .unwrap_or(t_ridge);
                let tree = eye + dir * t_tree;
                // Ground behind the ridge well under the sight line (a tree standing there is
                // hidden with 4 m to spare), and the ridge above the eye's horizon.
                // Near enough to cover many samples once above the ridge.
                if s_ridge > 0.02 && t_tree < 160.0 && inside(tree) && margin(t_tree) > TREE_M + 4.0 {
                    return (eye, yaw, s_ridge, t_tree);
                }
            }
        }
    }
    panic!("no ridge with low ground behind it in the synthetic dataset");
}

#[test]
fn a_tree_behind_a_ridge_is_hidden_and_shows_by_a_single_pixel_when_raised_into_view() {
    if impostors().is_none() {
        return;
    }
    let dataset = Dataset::open(&synth_dataset(RIDGE_DATASET.0, RIDGE_DATASET.1)).unwrap();
    let (eye, yaw, slope, t_tree) = ridge_view(&dataset);
    let [w, h] = dataset.manifest.extent_m();
    let pitch = slope.atan().to_degrees();
    let (r, camera) = settled(RIDGE_DATASET, RIDGE_IMAGE_PX, [eye.x / w, eye.y / h, 2.0, yaw, pitch]);
    let tree = species_of(&r, SpeciesKind::Tree);
    let dir = DVec2::new(yaw.to_radians().sin(), yaw.to_radians().cos());
    let xy = eye + dir * t_tree;
    let ground_m = r.dataset.height_at(xy.x, xy.y, 0).unwrap();
    let samples_at =
        |lift_m: f64| truth_of(&r, &camera, vec![seed(tree, 0, xy, ground_m + lift_m, TREE_M)]).samples[0];
    // Standing on its ground it is hidden, by the summit oracle too.
    assert_eq!(samples_at(0.0), 0);
    let eye_m = eye_grid(&r, &camera);
    let summit = DVec3::new(xy.x, xy.y, ground_m + TREE_M * (1.0 - r.settings.seeds.sink_fraction));
    assert!(!segment_clears_dem(&r.dataset, eye_m, summit).unwrap());
    // Raised well above the sight line it shows; between, the first lift that shows it (to the
    // centimetre) shows at most one pixel's samples: a leaf, not the tree.
    let (mut hidden, mut shown) = (0.0, eye_m.z + slope * t_tree - ground_m + 4.0);
    let whole = samples_at(shown + TREE_M);
    assert!(whole > 4 * u64::from(SUPERSAMPLE * SUPERSAMPLE), "{whole} samples");
    while shown - hidden > 0.01 {
        let mid = 0.5 * (hidden + shown);
        if samples_at(mid) == 0 { hidden = mid } else { shown = mid }
    }
    let first = samples_at(shown);
    println!(
        "hidden up to a lift of {hidden:.2} m; at {shown:.2} m, {first} samples show ({whole} when whole)"
    );
    assert!((1..=(SUPERSAMPLE * SUPERSAMPLE) as u64).contains(&first), "{first} samples");
}

#[test]
fn a_crown_poking_into_the_view_from_outside_it_is_visible() {
    if impostors().is_none() {
        return;
    }
    let (r, camera) = settled(DATASET, IMAGE_PX, [0.35, 0.35, 3.0, 45.0, 0.0]);
    let eye = eye_grid(&r, &camera);
    let view = Pinhole::new(&camera, IMAGE_PX.map(|n| n * SUPERSAMPLE));
    let tree = species_of(&r, SpeciesKind::Tree);
    let forward = DVec2::new(45f64.to_radians().sin(), 45f64.to_radians().cos());
    let right = -forward.perp();
    let height_m = 10.0;
    let half_width =
        (0.5 * camera.fov_deg.to_radians()).tan() * f64::from(IMAGE_PX[0]) / f64::from(IMAGE_PX[1]);
    // The trunk 25 m ahead, (1 + beyond) half-widths to the left: off screen, base and summit.
    let place = |beyond: f64| {
        let xy = eye.truncate() + forward * 25.0 - right * (25.0 * half_width * (1.0 + beyond));
        let ground_m = r.dataset.height_at(xy.x, xy.y, 0).unwrap();
        let base = DVec3::new(xy.x, xy.y, ground_m) - eye;
        let off_screen = [base, base + DVec3::Z * height_m].iter().all(|&p| view.ndc_x(p) < -1.0);
        let samples = truth_of(&r, &camera, vec![seed(tree, 0, xy, ground_m, height_m)]).samples[0];
        (off_screen, samples)
    };
    let poking = [0.02, 0.05, 0.1].map(place);
    println!("off screen, samples: {poking:?}");
    assert!(poking.iter().any(|&(off, n)| off && n > 0), "no crown poked in: {poking:?}");
    // Far enough out, nothing of it shows.
    assert_eq!(place(1.0), (true, 0));
}

#[test]
fn a_truth_grown_from_the_land_cover_is_written_whole() {
    let Some(impostors) = impostors() else { return };
    let dir = synth_dataset(DATASET.0, DATASET.1);
    let dataset = Dataset::open(&dir).unwrap();
    let settings = small_settings(IMAGE_PX[0], IMAGE_PX[1]);
    let r = terramp_testkit::renderer(&dir, settings.clone());
    let camera = camera::over_fraction(&r, [0.4, 0.4], 20.0, 30.0, -15.0);
    let eye = eye_grid(&r, &camera);
    drop(r);
    let options = TruthOptions { supersample: 2, reach_m: 300.0, impostors: impostors.to_owned() };
    let truth = render_truth(gpu(), dataset, &settings, &camera, &options).unwrap();
    let visible = truth.samples.iter().filter(|&&n| n > 0).count();
    println!(
        "{} seeds drawn of {} candidates, {visible} visible",
        truth.seeds.len(),
        truth.counts.candidates
    );
    assert!(visible > 10 && visible < truth.seeds.len());
    for s in &truth.seeds {
        let p = DVec3::new(s.position_grid_m[0], s.position_grid_m[1], s.ground_m);
        assert!((p - eye).length() < options.reach_m, "a seed beyond the reach: {s:?}");
    }
    let out = target_tmp_dir().join("truth-written");
    truth.write(&out).unwrap();
    let samples = (IMAGE_PX[0] * 2 * IMAGE_PX[1] * 2) as usize;
    let ids: Vec<u32> = bytemuck::pod_collect_to_vec(&std::fs::read(out.join(files::SEED_IDS_FILE)).unwrap());
    assert_eq!(ids, truth.seed_ids);
    assert_eq!(std::fs::read(out.join(files::DEPTH_FILE)).unwrap().len(), 4 * samples);
    assert_eq!(image::open(out.join(files::IMAGE_FILE)).unwrap().to_rgba8(), truth.colour);
    let csv = std::fs::read_to_string(out.join(files::SEEDS_FILE)).unwrap();
    assert_eq!(csv.lines().count(), truth.seeds.len() + 1);
    let shown: u64 = csv.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse::<u64>().unwrap()).sum();
    assert_eq!(shown as usize, ids.iter().filter(|&&id| id > 0).count());
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join(files::META_FILE)).unwrap()).unwrap();
    assert_eq!(meta["seeds_visible"], visible);
    assert_eq!(meta["samples_width"], IMAGE_PX[0] * 2);
    // One truth renderer over several views (a flight, a sweep's poses) gives each view's truth as
    // a fresh one does: nothing of the view before carries over.
    let mut other = camera;
    other.position_m += DVec3::new(30.0, -20.0, 5.0);
    other.yaw_deg += 15.0;
    let mut flight = TruthRenderer::new(gpu(), Dataset::open(&dir).unwrap(), &settings, &options).unwrap();
    let first = flight.render(&other).unwrap();
    let again = flight.render(&camera).unwrap();
    assert_ne!(first.colour, truth.colour, "the second view is a different view");
    assert!(
        again.colour == truth.colour && again.seed_ids == truth.seed_ids && again.depth == truth.depth,
        "a reused truth renderer differs from a fresh one"
    );
    // Bad options are errors, not pictures.
    let zero = TruthOptions { supersample: 0, ..options.clone() };
    let dataset = Dataset::open(&dir).unwrap();
    assert!(matches!(
        render_truth(gpu(), dataset, &settings, &camera, &zero),
        Err(terramp::truth::TruthError::Supersample)
    ));
    let none = TruthOptions { impostors: PathBuf::new(), ..options };
    let dataset = Dataset::open(&dir).unwrap();
    assert!(matches!(
        render_truth(gpu(), dataset, &settings, &camera, &none),
        Err(terramp::truth::TruthError::NoImpostors)
    ));
}
