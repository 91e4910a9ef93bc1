//! `examples/winit_host.rs` in a real window (Xvfb, lavapipe presenting): a host that draws its
//! own cubes and terramp's terrain and trees in one encoder, sharing the depth. Against the same
//! view rendered here by terramp alone (`Renderer::render`, the same settings, camera and size):
//! - with no cube, the host's frame is terramp's own view, within `OWN_VIEW_PSNR_DB`;
//! - a cube floating behind a ridge (every corner's ray meets the drawn ground first) changes no
//!   pixel: the terrain hides it;
//! - the same cube brought in front of the ridge, on the same ray (the control), shows;
//! - a cube in front of a tree, on the tree's pixel ray, hides the tree: the pixel is the cube's.
//!
//! Needs `Xvfb` (`.ci/run` installs it): without it the test fails under `CI=true` and is skipped,
//! saying so, elsewhere.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::Path;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp::reference::terrain::DrawnGround;
use terramp_testkit::setup::example;
use terramp_testkit::xvfb::Xvfb;
use terramp_testkit::{TempDir, camera, command, differing_pixels, gpu, psnr, synth_dataset};

const SIZE: [u32; 2] = [320, 180];
/// Frames the example draws before it saves its last: enough for the view to settle.
const FRAMES: u32 = 40;
/// Least PSNR of the host's frame with no cube against terramp's own render of the view, dB.
const OWN_VIEW_PSNR_DB: f64 = 35.0;
/// Least pixels the control (the same cube in front of the ridge) must change.
const SHOWN_PIXELS: usize = 20;
/// The cubes' side, metres.
const CUBE_M: f64 = 4.0;

/// The example's saved frame of `pose` with `cubes` (CRS x, y, z and side, metres).
fn host_frame(
    x: &Xvfb,
    dir: &Path,
    settings: &Path,
    pose: &Camera,
    cubes: &[DVec3],
    name: &str,
) -> image::RgbaImage {
    let p = pose.position_m;
    let camera = format!("{},{},{},{},{}", p.x, p.y, p.z, pose.yaw_deg, pose.pitch_deg);
    let out = dir.join(format!("{name}.png"));
    let mut run = command(example("winit_host"));
    run.arg(dir.join("dataset")).args(["--settings", settings.to_str().unwrap(), "--camera", &camera]);
    run.args(["--size", &format!("{}x{}", SIZE[0], SIZE[1]), "--frames", &FRAMES.to_string()]);
    // The software adapter, as the view rendered here (`WGPU_ADAPTER_NAME`, wgpu's own choice).
    run.args(["--save", out.to_str().unwrap()])
        .env("DISPLAY", &x.display)
        .env("WGPU_ADAPTER_NAME", "llvmpipe");
    for c in cubes {
        run.args(["--cube", &format!("{},{},{},{CUBE_M}", c.x, c.y, c.z)]);
    }
    let output = run.output().unwrap();
    assert!(output.status.success(), "{name}: {}", String::from_utf8_lossy(&output.stderr));
    image::open(&out).unwrap().to_rgba8()
}

/// A point behind a ridge: along the ray of some pixel, past the ground it meets, where a cube of
/// `CUBE_M` floats clear of the ground and every corner's ray meets the drawn ground first; and the
/// distance to that ground. Grid metres relative to the camera.
fn behind_a_ridge(r: &Renderer, ground: &DrawnGround) -> Option<(DVec3, f64)> {
    let half = 0.5 * CUBE_M;
    for y in (SIZE[1] / 4..SIZE[1] * 3 / 4).step_by(3) {
        for x in (SIZE[0] / 4..SIZE[0] * 3 / 4).step_by(6) {
            let direction = ground.pixel_ray([x, y]);
            let Some(hit) = ground.pick(direction) else { continue };
            let d = hit.rel_m.length();
            for step in 1..200 {
                let centre = direction * (d + 10.0 * f64::from(step));
                let grid = hit.grid_m - hit.rel_m + centre;
                let Ok(at) = r.ground_at(grid.x, grid.y) else { break };
                if grid.z - at.height_m < CUBE_M {
                    continue;
                }
                let corners = (0..8).map(|i| {
                    centre
                        + DVec3::new([-half, half][i & 1], [-half, half][(i >> 1) & 1], [-half, half][i >> 2])
                });
                if corners
                    .clone()
                    .all(|c| ground.pick(c).is_some_and(|g| g.rel_m.length() < c.length() - 1.0))
                {
                    return Some((centre, d));
                }
            }
        }
    }
    None
}

#[test]
fn the_winit_host_draws_its_cubes_among_terramps_terrain_and_trees() {
    let Some(x) = Xvfb::start(&["Xvfb"]) else { return };
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let tmp = TempDir::new("winit-host");
    std::os::unix::fs::symlink(synth_dataset(300, 7), tmp.path().join("dataset")).unwrap();
    let settings_file = tmp.path().join("trees.toml");
    std::fs::write(
        &settings_file,
        format!("[draw_seeds]\nimpostors = {:?}\n", impostors.display().to_string()),
    )
    .unwrap();
    let mut settings = Settings::load("balanced", Some(&settings_file)).unwrap();
    (settings.render.width, settings.render.height) = (SIZE[0], SIZE[1]);
    let mut r =
        Renderer::new(gpu(), terramp::dataset::Dataset::open(&tmp.path().join("dataset")).unwrap(), settings)
            .unwrap();
    // The first of these views (low over forest, looking along the relief) with a ridge to hide
    // a cube behind.
    let views =
        [([0.45, 0.35], 12.0, 20.0, -4.0), ([0.3, 0.6], 12.0, 100.0, -3.0), ([0.6, 0.3], 20.0, 250.0, -5.0)];
    let (pose, ground, (behind, ridge_m)) = views
        .iter()
        .find_map(|&(at, above_m, yaw, pitch)| {
            let pose = camera::over_fraction(&r, at, above_m, yaw, pitch);
            r.render_resolved(&pose).unwrap();
            let ground = r.drawn_ground().unwrap().unwrap();
            let ridge = behind_a_ridge(&r, &ground);
            println!(
                "view {at:?} {above_m} m up, heading {yaw}°: {}",
                if ridge.is_some() { "a ridge" } else { "no ridge" }
            );
            ridge.map(|ridge| (pose, ground, ridge))
        })
        .expect("no ridge in any view to hide a cube behind");
    let own = r.read_colour().unwrap();
    let (terrain, drawn) = (r.terrain_depth().unwrap(), r.read_depth().unwrap());

    let bare = host_frame(&x, tmp.path(), &settings_file, &pose, &[], "bare");
    let own_db = psnr(&bare, &own);
    println!("host frame against terramp's own: {own_db:.2} dB");

    let hidden = host_frame(&x, tmp.path(), &settings_file, &pose, &[pose.position_m + behind], "hidden");
    // Near enough to cover pixels: a hundred metres, or half-way to the ridge if that is nearer.
    let in_front = behind.normalize() * (0.5 * ridge_m).min(100.0);
    let shown = host_frame(&x, tmp.path(), &settings_file, &pose, &[pose.position_m + in_front], "shown");
    let (hidden_px, shown_px) = (differing_pixels(&hidden, &bare), differing_pixels(&shown, &bare));

    // A tree's pixel: nearer than the terrain there by metres, mid-screen.
    let tree = (0..terrain.len())
        .filter(|&i| (i as u32 % SIZE[0]).abs_diff(SIZE[0] / 2) < SIZE[0] / 3)
        .filter(|&i| drawn[i] > 0.0 && terrain[i] > 0.0 && drawn[i] > terrain[i] * 1.5)
        .max_by(|&a, &b| drawn[a].total_cmp(&drawn[b]))
        .expect("no tree in view");
    let px = [tree as u32 % SIZE[0], tree as u32 / SIZE[0]];
    let tree_m = ground.depth_point(px, drawn[tree]).length();
    let cube = ground.pixel_ray(px) * 0.5 * tree_m;
    let covered = host_frame(&x, tmp.path(), &settings_file, &pose, &[pose.position_m + cube], "covered");
    let (before, after) = (bare.get_pixel(px[0], px[1]).0, covered.get_pixel(px[0], px[1]).0);
    println!(
        "host frame against terramp's own: {own_db:.2} dB; a cube {:.0} m away behind a ridge {ridge_m:.0} m away: \
         {hidden_px} pixels changed against the bare frame, brought in front (the control) {shown_px}; the tree at pixel \
         {px:?}, {tree_m:.1} m away: {before:?} bare, {after:?} with a cube at half its distance",
        behind.length()
    );
    assert!(own_db >= OWN_VIEW_PSNR_DB, "{own_db} dB");
    assert_eq!(hidden_px, 0, "the cube behind the ridge shows");
    assert!(shown_px >= SHOWN_PIXELS, "the control passes: {shown_px} pixels");
    // The cube's magenta (its faces' red equals their blue; no green) where the tree was.
    assert!(after[1] < 10 && after[0].abs_diff(after[2]) < 10 && after[0] > 100, "{after:?}");
    assert_ne!(before, after);
}
