//! Pass 4 on `nc/` (DEM, Landsat, land use): the shared models are baked into impostors once per
//! test process (`terramp-data bake`), and a view over forest near the lake is rendered with
//! `draw_seeds.impostors` set and with it empty. The trees change many pixels, make them darker or
//! greener, never stand behind the terrain (depth only grows nearer) and leave the sky well above
//! the horizon alone. Under each pixel the bare frame's depth gives the ground and its land-cover
//! class: most forest pixels show trees, and no pixel of open water does (water that no tree on
//! land in front of it could reach up or across to). The frame matches its reference image
//! (`terramp_testkit::Golden`, 60 dB), which the frame without trees, its control, misses by far;
//! `scripts/bless_references.sh` makes the last rendered frame the reference after an intended
//! change of the look.
//! (Per seed, that no tree stands on water is pass 3's test: `tests/seeds.rs`.)
//!
//! The figure `docs/nc_trees.png` (960×540, accurate preset) comes from the ignored test:
//! `WGPU_BACKEND=vulkan cargo test --release -p terramp-data-tools --test draw_seeds -- --ignored`.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::{FrameReport, Renderer};
use terramp::reference::frame_change::largest_block_change;
use terramp::reference::seed_select::SeedComparison;

use support::{FOREST, WATER, build_nc, forest_near_water, ground_under_pixels, tests_dir};
use terramp_testkit::{Golden, TempDir, shared_data};

/// The test's view: metres above the forest, and pitch (degrees) down towards the lake: high
/// and steep enough that trees on the near shore leave much of the lake uncovered.
const VIEW: [f64; 2] = [120.0, -22.0];
/// The frame with trees, balanced preset, 320×180.
const REFERENCE: &str = "reference/nc_trees_320x180.png";
/// lavapipe renders this frame 70.6 dB from the reference an earlier renderer blessed (measured
/// 2026-12-06); the tolerance leaves room for another build's last bits of filtering and coverage
/// only. The control, the frame without
/// trees, is 19.9 dB from the reference, so the trees cannot go missing.
const MIN_PSNR_DB: f64 = 60.0;

/// The species models of the nc table, baked once per test process into the target's temporary
/// folder (each model's folder is replaced atomically, so a concurrent reader sees a whole one).
fn impostors() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("draw_seeds-impostors");
        let models = shared_data().expect("../shared/data").join("models");
        let table = terramp::classes::ClassTable::load("nc").unwrap();
        let mut args = vec!["bake".to_owned()];
        for s in &table.species {
            args.extend([
                "--model".to_owned(),
                models.join(format!("{}.glb", s.model)).display().to_string(),
            ]);
        }
        args.extend(["--out".into(), out.display().to_string(), "--texels".into(), "256".into()]);
        let output =
            terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data")).args(&args).output().unwrap();
        let (stdout, stderr) =
            (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
        assert!(output.status.success(), "bake failed:\n{stdout}\n{stderr}");
        out
    })
}

/// A renderer over `pose` seen from `[above_m, pitch_deg]`, every tile resident and the seeds of
/// the final TLM selected (seeds follow the TLM of a frame or two before).
fn open_view(
    dataset: Dataset,
    mut settings: Settings,
    impostors: &str,
    size: [u32; 2],
    pose: ([f64; 2], f64),
    [above_m, pitch_deg]: [f64; 2],
) -> (Renderer, Camera, FrameReport) {
    settings.render.width = size[0];
    settings.render.height = size[1];
    settings.draw_seeds.impostors = impostors.to_owned();
    let gpu = terramp_testkit::gpu();
    let mut r = Renderer::new(gpu, dataset, settings).unwrap();
    let ([x, y], yaw_deg) = pose;
    let camera = terramp_testkit::camera::over(&r, [x, y], above_m, yaw_deg, pitch_deg);
    r.render_resolved(&camera).unwrap();
    let mut report = r.render(&camera).unwrap();
    for _ in 0..4 {
        report = r.render(&camera).unwrap();
    }
    (r, camera, report)
}

fn render(
    dataset: Dataset,
    settings: Settings,
    impostors: &str,
    size: [u32; 2],
    pose: ([f64; 2], f64),
    view: [f64; 2],
) -> (image::RgbaImage, Vec<f32>, FrameReport, Camera) {
    let (r, camera, report) = open_view(dataset, settings, impostors, size, pose, view);
    (r.read_colour().unwrap(), r.read_depth().unwrap(), report, camera)
}

#[test]
fn nc_forest_draws_trees() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("draw-seeds");
    let path = tmp.path().join("nc");
    let dataset = build_nc(&path);
    let pose = forest_near_water(&dataset);
    let dir = impostors().to_str().unwrap().to_owned();
    let size = [320, 180];
    let (bare, bare_depth, bare_report, camera) = render(dataset, Settings::default(), "", size, pose, VIEW);
    let reopened = Dataset::open(&path).unwrap();
    let (trees, depth, report, _) = render(reopened, Settings::default(), &dir, size, pose, VIEW);
    assert_eq!((bare_report.seed_species_drawn, bare_report.seed_species_undrawn), (0, 9));
    assert_eq!((report.seed_species_drawn, report.seed_species_undrawn), (9, 0), "{report:?}");
    assert!(report.seeds.is_some_and(|s| s.counters.selected > 0), "{report:?}");

    assert!(depth.iter().all(|d| d.is_finite() && (0.0..=1.0).contains(d)), "NaN or odd depth");
    let luma =
        |p: &image::Rgba<u8>| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
    let green =
        |p: &image::Rgba<u8>| f64::from(p[1]) / (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]) + 1.0);
    let (mut changed, mut sky, mut sky_changed, mut high_sky_changed) = (0usize, 0usize, 0usize, 0usize);
    // Rows more than 6° above the horizontal (the pitch and the vertical field of view, 60°).
    let rows_up = |deg: f64| {
        let t = ((deg - VIEW[1]).to_radians().tan() / 30f64.to_radians().tan()).min(1.0);
        ((1.0 - t) * 0.5 * f64::from(size[1])).floor() as usize
    };
    let high = rows_up(6.0) * size[0] as usize;
    let (mut luma_delta, mut green_delta) = (0.0, 0.0);
    for (i, (a, b)) in bare.pixels().zip(trees.pixels()).enumerate() {
        // Reversed-Z: a tree is only ever nearer than the ground it stands before.
        assert!(
            depth[i] >= bare_depth[i],
            "pixel {i}: depth {} behind the terrain's {}",
            depth[i],
            bare_depth[i]
        );
        let differs = a.0[..3].iter().zip(&b.0[..3]).any(|(x, y)| x.abs_diff(*y) > 2);
        if bare_depth[i] == 0.0 {
            sky += 1;
            sky_changed += usize::from(differs);
            high_sky_changed += usize::from(differs && i < high);
        }
        if differs {
            changed += 1;
            luma_delta += luma(b) - luma(a);
            green_delta += green(b) - green(a);
        }
    }
    let total = bare.pixels().len();
    println!(
        "{changed} of {total} pixels changed (mean luma {:+.1}, greenness {:+.3}); {sky_changed} of {sky} sky pixels",
        luma_delta / changed.max(1) as f64,
        green_delta / changed.max(1) as f64
    );
    assert!(changed > total / 50, "only {changed} of {total} pixels show trees");
    assert!(luma_delta < 0.0 || green_delta > 0.0, "trees neither darken nor green the ground");
    // Trees on the skyline cover some sky; well above the horizon (over 6° up) nothing stands.
    assert!(sky_changed * 10 <= sky.max(1), "{sky_changed} of {sky} sky pixels changed");
    assert_eq!(high_sky_changed, 0, "trees in the sky high above the horizon");

    let reopened = Dataset::open(&path).unwrap();
    trees_stand_on_forest_not_on_water(&reopened, &camera, size, &bare, &bare_depth, &trees);
    // Without the trees the frame is far from the reference: the tolerance cannot hide them.
    let golden = Golden { tests_dir: &tests_dir(), name: REFERENCE, min_db: MIN_PSNR_DB };
    golden.check(&terramp_testkit::gpu(), &trees, &bare);
}

/// With the trees drawn, pass 3's twin still reads what pass 3 read: the terrain's depth. The depth
/// target holds the trees by then; a twin reading it would hide the seeds behind near trees from
/// itself alone, and differ from the GPU.
#[test]
fn the_seed_twin_reads_the_terrain_depth_with_trees_drawn() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("draw-seeds-twin");
    let dataset = build_nc(&tmp.path().join("nc"));
    let pose = forest_near_water(&dataset);
    let dir = impostors().to_str().unwrap().to_owned();
    let (r, _, report) = open_view(dataset, Settings::default(), &dir, [320, 180], pose, VIEW);
    assert_eq!(report.seed_species_drawn, 9, "{report:?}");
    let (terrain, drawn) = (r.terrain_depth().unwrap(), r.read_depth().unwrap());
    let nearer = drawn.iter().zip(&terrain).filter(|(d, t)| d > t).count();
    assert!(nearer > drawn.len() / 50, "only {nearer} pixels of trees in the depth target");
    assert!(drawn.iter().zip(&terrain).all(|(d, t)| d >= t), "a tree behind the terrain");
    let (gpu, gpu_counters) = r.read_seeds().unwrap().unwrap();
    let (twin, twin_counters) = r.seed_twin().unwrap().unwrap();
    let diff = SeedComparison::of(&gpu, &twin);
    println!(
        "{} seeds with trees drawn: {} common; {nearer} pixels of trees in the depth",
        gpu.len(),
        diff.common
    );
    assert_eq!(gpu_counters, twin_counters);
    assert!(
        diff.only_gpu.is_empty() && diff.only_twin.is_empty(),
        "{} GPU-only, {} twin-only",
        diff.only_gpu.len(),
        diff.only_twin.len()
    );
    assert!(diff.mismatched.is_empty() && diff.non_finite.is_empty(), "{diff:?}");
    assert_eq!(diff.max_length_error_m, 0.0);
}

/// Where the pixels the trees changed stand, by the ground under each pixel of the bare frame:
/// over forest most pixels change; over water, a pixel changes only if a tree on land in front
/// of it (below it on screen, within the tallest tree's height in pixels there and its crown's
/// width) can cover it.
fn trees_stand_on_forest_not_on_water(
    dataset: &Dataset,
    camera: &Camera,
    size: [u32; 2],
    bare: &image::RgbaImage,
    bare_depth: &[f32],
    trees: &image::RgbaImage,
) {
    let [w, h] = size;
    let ground: Vec<Option<(u8, f64)>> = ground_under_pixels(dataset, camera, size, bare_depth, true)
        .into_iter()
        .map(|g| g.map(|g| (g.code, g.distance_m)))
        .collect();
    let table = terramp::classes::ClassTable::load("nc").unwrap();
    let tallest_m = table.species.iter().map(|s| f64::from(s.height_m[1])).fold(0.0, f64::max);
    let widest = table.species.iter().map(|s| f64::from(s.radius_per_height)).fold(0.0, f64::max);
    let changed = |i: usize| {
        let (a, b) = (&bare.as_raw()[4 * i..4 * i + 3], &trees.as_raw()[4 * i..4 * i + 3]);
        a.iter().zip(b).any(|(a, b)| a.abs_diff(*b) > 2)
    };
    // What a tree standing on each land pixel could cover: the tallest tree's height in pixels
    // at that distance above it, and its widest crown either side.
    let mut shadow = vec![false; (w * h) as usize];
    for (i, g) in ground.iter().enumerate() {
        let Some((code, distance_m)) = *g else { continue };
        if code == WATER {
            continue;
        }
        let reach_px = (tallest_m / camera.metres_per_pixel(distance_m, h)).ceil() as i64 + 1;
        let half_px = (reach_px as f64 * widest).ceil() as i64 + 1;
        let (x, y) = ((i as u32 % w) as i64, (i as u32 / w) as i64);
        for yy in (y - reach_px).max(0)..=y {
            for xx in (x - half_px).max(0)..=(x + half_px).min(i64::from(w) - 1) {
                shadow[(yy * i64::from(w) + xx) as usize] = true;
            }
        }
    }
    let (mut forest, mut forest_changed, mut open_water, mut water_changed) = (0, 0, 0, 0);
    for i in 0..(w * h) as usize {
        let Some((code, distance_m)) = ground[i] else { continue };
        if code == FOREST && distance_m < 1000.0 {
            forest += 1;
            forest_changed += usize::from(changed(i));
        }
        if code == WATER && !shadow[i] {
            open_water += 1;
            water_changed += usize::from(changed(i));
        }
    }
    println!(
        "forest within 1 km: {forest_changed} of {forest} pixels show trees; open water: {water_changed} of {open_water}"
    );
    assert!(
        forest > 500 && forest_changed * 2 > forest,
        "{forest_changed} of {forest} forest pixels show trees"
    );
    assert!(open_water > 200, "only {open_water} pixels of open water in view: a weak test");
    assert_eq!(water_changed, 0, "trees on the lake");
}

/// Largest changes between consecutive frames: of one pixel's luma, and of a 4 × 4 block's mean
/// luma (`frame_change`: the dither's period, so a cross-fade flips single pixels, a pop changes
/// whole blocks).
fn frame_change(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, f64) {
    let luma =
        |p: &image::Rgba<u8>| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
    let (w, h) = a.dimensions();
    let delta = |x: u32, y: u32| luma(b.get_pixel(x, y)) - luma(a.get_pixel(x, y));
    let pixel =
        (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| delta(x, y).abs()).fold(0.0, f64::max);
    (pixel, largest_block_change(a, b).unwrap())
}

/// A slow change of distance, with everything else still: the camera stays, and every seed's LOD
/// reaches shrink by 0.2 % a frame (`seeds.reference_height_m` grows above every tree's height),
/// as if the view drew back at 0.2 % of each distance a frame (1.4 m at 700 m). Every change
/// between frames is then a LOD change. With the cross-fade (`seeds.fade_fraction` 0.1) the
/// largest change of a 4 × 4 block between frames stays under 12 levels of 255 and under half of
/// what switching at once gives (measured on lavapipe: 7.4 against 15.2). Single pixels still
/// flip between the two LODs' geometry (up to ~140 levels either way): that is the dither. In a
/// 12 m/s wind held at one moment the figure stays within 20 % of still air's (issue 14): every
/// LOD of a seed bends the same way. Where a class stops its seeds at an earlier LOD
/// (`[[class]] seed_lods`), they fade out there just as softly: within the same 12 levels and
/// half of what stopping at once gives.
#[test]
fn lod_changes_cross_fade_instead_of_popping() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("draw-seeds-fade");
    let path = tmp.path().join("nc");
    let pose = forest_near_water(&build_nc(&path));
    let dir = impostors().to_str().unwrap().to_owned();
    // nc's table with every class drawing its seeds to the first billboard-cloud band only (the
    // forest without texcells, which take over only after the last band).
    let nc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/classes/nc.toml"))
        .unwrap();
    let near = nc.replace("texcells = true\n", "").replace("\n[[class]]\n", "\n[[class]]\nseed_lods = 2\n");
    let near_table = tmp.path().join("near.toml");
    std::fs::write(&near_table, near).unwrap();
    let run_with = |fade_fraction: f64, wind_m_s: f64, class_table: &str| {
        let mut settings = Settings::default();
        settings.draw_seeds.fade_fraction = fade_fraction;
        settings.seeds.reference_height_m = 40.0;
        settings.seeds.class_table = class_table.to_owned();
        settings.wind.speed_m_s = wind_m_s;
        let (mut r, camera, _) =
            open_view(Dataset::open(&path).unwrap(), settings, &dir, [320, 180], pose, [40.0, -12.0]);
        // One moment of the wind throughout: only the LODs change between frames.
        r.set_time_s(6.0);
        r.render(&camera).unwrap();
        r.render(&camera).unwrap();
        let mut frames = vec![r.read_colour().unwrap()];
        for _ in 0..FADE_FRAMES {
            r.settings.seeds.reference_height_m *= 1.002;
            // Pass 3 runs a frame behind the draw's constants: two frames per step.
            r.render(&camera).unwrap();
            r.render(&camera).unwrap();
            frames.push(r.read_colour().unwrap());
        }
        let changes: Vec<(f64, f64)> = frames.windows(2).map(|f| frame_change(&f[0], &f[1])).collect();
        let worst = changes.iter().fold((0.0f64, 0.0f64), |a, c| (a.0.max(c.0), a.1.max(c.1)));
        println!(
            "fade {fade_fraction}, wind {wind_m_s} m/s, table {class_table:?}: largest change of a pixel {:.1}, of a 4×4 block {:.1} (of 255)",
            worst.0, worst.1
        );
        worst
    };
    let run = |fade_fraction: f64, wind_m_s: f64| run_with(fade_fraction, wind_m_s, "");
    let (_, faded) = run(0.1, 0.0);
    let (_, popped) = run(0.0, 0.0);
    // Both real: a fade that changed nothing would pass any bound below (no LOD changed).
    assert!(popped > 0.0 && faded > 0.0, "nothing changed LOD in {FADE_FRAMES} frames: a void test");
    assert!(
        faded <= MAX_FADE_OF_POP * popped,
        "cross-fades change a block by {faded:.1}, pops by {popped:.1}"
    );
    assert!(
        faded <= MAX_FADE_BLOCK_CHANGE,
        "cross-fades change a 4×4 block by {faded:.1} of 255 in one frame"
    );
    // Control: switching at once fails the bound the fades meet.
    assert!(popped > MAX_FADE_BLOCK_CHANGE, "switching at once changes a block by only {popped:.1}");
    // The mesh and the clouds bend alike in the wind, so the switch between them shows no more.
    let (_, windy) = run(0.1, 12.0);
    assert!(
        windy <= MAX_WIND_OF_STILL * faded,
        "in a 12 m/s wind cross-fades change a block by {windy:.1}, still {faded:.1}"
    );
    let near_table = near_table.to_str().unwrap();
    let (_, class_faded) = run_with(0.1, 0.0, near_table);
    let (_, class_stopped) = run_with(0.0, 0.0, near_table);
    assert!(
        class_stopped > 0.0 && class_faded > 0.0,
        "no seed left its class's last LOD in {FADE_FRAMES} frames: a void test"
    );
    assert!(
        class_faded <= MAX_CLASS_FADE_BLOCK_CHANGE && class_faded <= MAX_FADE_OF_POP * class_stopped,
        "fading out at their class's last LOD, seeds change a block by {class_faded:.1}; stopping at once, {class_stopped:.1}"
    );
}

/// Steps of the slow distance change.
const FADE_FRAMES: usize = 24;
/// Most a cross-fade may change a 4 × 4 block's mean luma between frames, levels of 255: above
/// lavapipe's 10.4 (7.4 before the atmosphere's sky stood behind the far trees), under a pop
/// (23.1).
const MAX_FADE_BLOCK_CHANGE: f64 = 12.0;
/// The same for seeds fading out at their class's last LOD: they stand on the horizon, against
/// the sky's bright horizon band, where a block's change is about twice a cross-fade's (lavapipe:
/// 17.5, against 39.5 stopping at once).
const MAX_CLASS_FADE_BLOCK_CHANGE: f64 = 20.0;
/// Most a cross-fade's largest block change may be of switching at once's in the same frames: a
/// fade that took out less than half of a pop would not be one.
const MAX_FADE_OF_POP: f64 = 0.5;
/// Most the largest block change may grow in a 12 m/s wind, over still air's: issue 14's 20 %.
const MAX_WIND_OF_STILL: f64 = 1.2;

/// Makes `docs/nc_trees.png`: 960×540, accurate preset, over nc forest looking towards a lake.
#[test]
#[ignore = "writes the figure docs/nc_trees.png"]
fn nc_trees_figure() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("draw-seeds-figure");
    let dataset = build_nc(&tmp.path().join("nc"));
    let pose = forest_near_water(&dataset);
    let dir = impostors().to_str().unwrap().to_owned();
    let settings = Settings::preset("accurate").unwrap();
    let (image, _, report, _) = render(dataset, settings, &dir, [960, 540], pose, [40.0, -12.0]);
    println!("{report:?}");
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/nc_trees.png");
    image.save(&out).unwrap();
    println!("wrote {}", out.display());
}
