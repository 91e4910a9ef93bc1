//! Terrain rendering on the software adapter: frames are not blank, keep their depth, have no
//! holes between LODs, repeat exactly, and survive cameras outside the dataset; a command says
//! when seeds are selected that nothing can draw.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DVec3;
use terramp::camera::Camera;
use terramp::frame::{RenderError, Renderer};
use terramp::gpu::{GpuError, TimeSource};

use terramp_testkit::camera::over_fraction;
use terramp_testkit::{renderer, small_settings, synth_dataset};

/// Depth rows, top first.
fn depth_rows(renderer: &Renderer) -> Vec<Vec<f32>> {
    let width = renderer.settings.render.width as usize;
    renderer.read_depth().unwrap().chunks(width).map(<[f32]>::to_vec).collect()
}

#[test]
fn frame_shows_ground_and_sky_and_keeps_depth() {
    let dataset = synth_dataset(300, 7);
    let mut r = renderer(&dataset, small_settings(160, 96));
    let camera = over_fraction(&r, [0.5, 0.5], 300.0, 30.0, -10.0);
    let report = r.render(&camera).unwrap();
    assert!(report.nodes_drawn > 0 && report.nodes_dropped == 0, "{report:?}");
    let rows = depth_rows(&r);
    assert!(rows[0].iter().all(|&d| d == 0.0), "the top row looks at the sky");
    assert!(rows[95].iter().all(|&d| d > 0.0 && d <= 1.0), "the bottom row looks at the ground");
    let image = r.read_colour().unwrap();
    let lum: Vec<f64> = image.pixels().map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])).collect();
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    let variance = lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64;
    assert!(variance > 100.0, "the frame is nearly uniform (variance {variance})");
}

#[test]
fn no_holes_below_the_horizon_across_lods() {
    let dataset = synth_dataset(600, 3);
    let mut settings = small_settings(200, 120);
    settings.terrain.triangle_px = 2.0;
    settings.terrain.node_cells = 16;
    let mut r = renderer(&dataset, settings);
    for (yaw, pitch) in [(0.0, -25.0), (135.0, -40.0), (250.0, -15.0)] {
        let camera = over_fraction(&r, [0.5, 0.5], 150.0, yaw, pitch);
        r.render(&camera).unwrap();
        let rows = depth_rows(&r);
        for x in 0..rows[0].len() {
            // Scanning down a column, once the ground is hit, only ground follows: a sky pixel
            // below it is a crack between nodes or LODs.
            let first = rows.iter().position(|row| row[x] > 0.0).unwrap_or(rows.len());
            let hole = rows[first..].iter().position(|row| row[x] == 0.0);
            assert!(hole.is_none(), "yaw {yaw}: hole at column {x}, row {}", first + hole.unwrap_or(0));
        }
    }
}

#[test]
fn the_same_view_renders_the_same_pixels() {
    let dataset = synth_dataset(300, 7);
    let mut r = renderer(&dataset, small_settings(128, 80));
    let camera = over_fraction(&r, [0.5, 0.5], 200.0, 200.0, -20.0);
    r.render_resolved(&camera).unwrap();
    let first = r.read_colour().unwrap();
    // Move away and back: cache state differs, the resolved image must not.
    r.render_resolved(&over_fraction(&r, [0.5, 0.5], 2000.0, 10.0, -60.0)).unwrap();
    r.render_resolved(&camera).unwrap();
    assert!(first == r.read_colour().unwrap());
}

#[test]
fn cameras_outside_the_dataset_look_in() {
    let dataset = synth_dataset(300, 7);
    let mut r = renderer(&dataset, small_settings(128, 80));
    let m = r.dataset.manifest.clone();
    let corner = m.corner_m();
    // South-west of the corner, high, looking north-east at the dataset.
    let camera = Camera {
        position_m: DVec3::new(corner[0] - 500.0, corner[1] - 500.0, f64::from(m.height.max_m) + 800.0),
        yaw_deg: 45.0,
        pitch_deg: -25.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: 0.1,
    };
    let report = r.render(&camera).unwrap();
    assert!(report.nodes_drawn > 0);
    assert!(r.read_depth().unwrap().iter().any(|&d| d > 0.0));
    // Looking away from it: nothing to draw, and that is fine.
    let away = Camera { yaw_deg: 225.0, ..camera };
    assert_eq!(r.render(&away).unwrap().nodes_drawn, 0);
}

#[test]
fn no_adapter_is_a_clear_error_not_a_panic() {
    let dataset = synth_dataset(300, 7);
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"))
        .args(["render", "--dataset"])
        .arg(&dataset)
        .args(["--camera", "100,100,900,0,-10", "--width", "32", "--height", "32", "--out"])
        .arg(std::env::temp_dir().join("terramp-no-adapter.png"))
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(stderr.contains("mesa-vulkan-drivers") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn passes_are_timed_with_timestamps_or_on_the_cpu() {
    let dataset = synth_dataset(300, 7);
    for timestamps in [true, false] {
        let mut settings = small_settings(96, 64);
        settings.gpu.timestamps = timestamps;
        let mut r = renderer(&dataset, settings);
        let camera = over_fraction(&r, [0.5, 0.5], 300.0, 30.0, -10.0);
        for _ in 0..3 {
            r.render(&camera).unwrap();
        }
        let frames = r.profiler.drain(&r.gpu).unwrap();
        let last = frames.last().map(Vec::as_slice).unwrap_or(r.last_timings());
        let terrain = last.iter().find(|t| t.label == "terrain").expect("the terrain pass is timed");
        let expected =
            if timestamps && r.gpu.has_timestamps { TimeSource::GpuTimestamps } else { TimeSource::CpuWait };
        assert_eq!(terrain.source, expected);
        assert!(terrain.ms > 0.0 && terrain.ms.is_finite(), "{terrain:?}");
        assert!(last.iter().any(|t| t.label == "terrain_select" && t.source == TimeSource::Cpu));
    }
}

/// A headless command opens its GPU without probing a window system: Mesa's device-select layer
/// would connect to Wayland and X11 and print errors a user cannot act on.
#[test]
fn a_headless_render_prints_no_window_system_errors() {
    let dataset = synth_dataset(300, 7);
    let output = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"))
        .args(["render", "--dataset"])
        .arg(&dataset)
        .args(["--camera", "100,100,900,0,-10", "--width", "32", "--height", "32", "--out"])
        .arg(std::env::temp_dir().join(format!("terramp-quiet-{}.png", std::process::id())))
        .env_remove("NODEVICE_SELECT")
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("DISPLAY")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("XDG_RUNTIME_DIR") && !stderr.contains("error:"), "{stderr}");
}

#[test]
fn a_lost_device_is_an_error_not_a_panic() {
    let dataset = synth_dataset(300, 3);
    let mut r = renderer(&dataset, small_settings(96, 54));
    let camera = over_fraction(&r, [0.5, 0.5], 200.0, 30.0, -20.0);
    r.render(&camera).unwrap();
    // What a driver reset or a removed GPU does to wgpu's device, on demand.
    r.gpu.device.destroy();
    let errors: Vec<RenderError> = (0..6).map(|_| r.render(&camera).unwrap_err()).collect();
    let lost =
        |e: &RenderError| matches!(e, RenderError::Gpu(GpuError::DeviceLost(why)) if why == "Destroyed");
    let first = errors.iter().position(lost).unwrap_or_else(|| panic!("never told of the loss: {errors:?}"));
    assert_eq!(first, 0, "the first frame after the loss must say so: {errors:?}");
    assert!(errors[first..].iter().all(lost), "once lost, always lost: {errors:?}");
    let said = errors[first].to_string();
    assert!(said.starts_with("the GPU device was lost (Destroyed); nothing more can be drawn"), "{said}");
}

/// `terramp render` of `dataset` with the settings file `settings` (if any): its standard error.
fn render_stderr(dataset: &std::path::Path, settings: Option<&std::path::Path>) -> String {
    let mut command = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"));
    command.args(["render", "--dataset"]).arg(dataset);
    command.args(["--camera", "100,100,900,0,-10", "--width", "32", "--height", "32", "--out"]);
    command.arg(std::env::temp_dir().join(format!("terramp-undrawn-{}.png", std::process::id())));
    if let Some(file) = settings {
        command.arg("--settings").arg(file);
    }
    let output = command.output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(output.status.success(), "{stderr}");
    stderr
}

/// Seeds selected that nothing can draw are said, by the library's `UndrawnSeeds` and by the
/// commands as they start: no impostor folder, a folder without some of the table's models; and
/// not said when every model is there, or when no seed is selected.
#[test]
fn seeds_selected_but_not_drawn_are_said() {
    use terramp::config::Settings;
    use terramp::dataset::Dataset;
    use terramp::frame::UndrawnSeeds;
    let dir = synth_dataset(300, 7);
    let dataset = Dataset::open(&dir).unwrap();
    let models: Vec<String> = {
        let mut models = Vec::new();
        for s in terramp::classes::ClassTable::load("nc").unwrap().species {
            if !models.contains(&s.model) {
                models.push(s.model);
            }
        }
        models
    };
    assert!(models.len() > 2, "{models:?}");
    let with = |impostors: &str, density_scale: f64| {
        let mut settings = Settings::default();
        settings.draw_seeds.impostors = impostors.to_owned();
        settings.seeds.density_scale = density_scale;
        UndrawnSeeds::of(&dataset, &settings).unwrap()
    };
    let none = with("", 1.0).expect("no impostor folder: nothing drawn");
    assert_eq!((none.class_table.as_str(), &none.missing), ("nc", &models));
    assert!(
        none.to_string().contains("are selected but none is drawn: draw_seeds.impostors names"),
        "{none}"
    );
    assert_eq!(with("", 0.0), None, "no seed selected, nothing to say");
    let said = render_stderr(&dir, None);
    assert!(said.contains(&format!("terramp: {none}")), "{said}");

    let Some(baked) = terramp_testkit::nc_impostors() else { return };
    assert_eq!(with(baked.to_str().unwrap(), 1.0), None, "every model baked");
    let tmp = terramp_testkit::TempDir::new("undrawn");
    let settings = tmp.path().join("settings.toml");
    std::fs::write(&settings, format!("[draw_seeds]\nimpostors = {:?}\n", baked.display().to_string()))
        .unwrap();
    let said = render_stderr(&dir, Some(&settings));
    assert!(!said.contains("drawn"), "{said}");
    // A folder with all but the first two models.
    let partial = tmp.path().join("partial");
    std::fs::create_dir_all(&partial).unwrap();
    for model in &models[2..] {
        std::os::unix::fs::symlink(baked.join(model), partial.join(model)).unwrap();
    }
    let some = with(partial.to_str().unwrap(), 1.0).expect("two models missing");
    assert_eq!(some.missing, models[..2]);
    let expected = format!(
        "2 of the class table nc's {} models have no impostor in {}",
        models.len(),
        partial.display()
    );
    assert!(some.to_string().starts_with(&expected), "{some}");
}
