//! `terramp view` in a real window: an X server of its own (Xvfb), the software adapter presenting
//! to it, and a person's input sent through X (xdotool). The test opens the viewer over a small
//! synthetic dataset with trees, waits for its first frame, captures the window (xwd), flies
//! (W held, a drag), saves a screenshot with F12, captures the window with the overlay and
//! without it (H), and checks:
//! - the terrain is there (the 3D region is not blank) and so is the overlay (where it is drawn
//!   the window differs from the frame under it, and it holds bright text on a dark panel);
//! - the view moved (the window before the flight differs from the window after);
//! - the F12 screenshot's own `terramp render` line, run headless, gives the window's 3D frame
//!   within `WINDOW_PSNR_DB` (58.2 dB measured: the window shows the renderer's bytes unchanged,
//!   but the render line gives the pose to a millimetre and a thousandth of a degree, so the
//!   headless view is not quite the window's).
//!
//! Needs `Xvfb`, `xdotool` and `xwd` (`.ci/run` installs them): without them the test fails under
//! `CI=true` and is skipped, saying so, elsewhere.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use terramp_testkit::xvfb::Xvfb;
use terramp_testkit::{TempDir, psnr, synth_dataset};

/// Least PSNR between the window's 3D frame and the same view rendered headless, dB.
const WINDOW_PSNR_DB: f64 = 40.0;
/// The window's size, pixels (Xvfb has no HiDPI: one pixel per point).
const WINDOW_PX: [u32; 2] = [640, 360];
/// Longest wait for the viewer to open, fly or save (a hang guard, not a timing).
const PATIENCE: Duration = Duration::from_secs(300);

/// Kills its process when dropped, so a failing test leaves no X server or viewer behind.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Runs an X client against `display`, checking that it succeeded; its standard output.
fn x(display: &str, program: &str, args: &[&str]) -> Vec<u8> {
    let out = Command::new(program).args(args).env("DISPLAY", display).output().unwrap();
    assert!(out.status.success(), "{program} {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out.stdout
}

/// The window `id` as xwd captures it, as RGBA.
fn capture(display: &str, id: &str) -> image::RgbaImage {
    xwd_image(&x(display, "xwd", &["-id", id, "-silent"]))
}

/// An XWD file (X Window Dump, the format `xwd` writes) of a 24- or 32-bit TrueColor window.
fn xwd_image(bytes: &[u8]) -> image::RgbaImage {
    let word = |i: usize| u32::from_be_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
    let (header, width, height, byte_order) = (word(0) as usize, word(4), word(5), word(7));
    let (bits_per_pixel, bytes_per_line, colours) = (word(11), word(12) as usize, word(19) as usize);
    let masks = [word(14), word(15), word(16)];
    assert_eq!(bits_per_pixel, 32, "a 24-bit display stores 32-bit pixels");
    let pixels = &bytes[header + 12 * colours..];
    image::RgbaImage::from_fn(width, height, |px, py| {
        let at = py as usize * bytes_per_line + 4 * px as usize;
        let raw: [u8; 4] = pixels[at..at + 4].try_into().unwrap();
        let v = if byte_order == 0 { u32::from_le_bytes(raw) } else { u32::from_be_bytes(raw) };
        let [r, g, b] = masks.map(|m| ((v & m) >> m.trailing_zeros()) as u8);
        image::Rgba([r, g, b, 255])
    })
}

/// Waits for a line of the viewer's output that contains `needle`; returns it.
fn wait_for(lines: &mpsc::Receiver<String>, needle: &str) -> String {
    loop {
        match lines.recv_timeout(PATIENCE) {
            Ok(line) if line.contains(needle) => return line,
            Ok(_) => {}
            Err(e) => panic!("the viewer never said `{needle}`: {e}"),
        }
    }
}

/// Pixels of `a` and `b` differing by more than a rounding.
fn changed(a: &image::RgbaImage, b: &image::RgbaImage) -> Vec<(u32, u32)> {
    a.enumerate_pixels()
        .filter(|(x, y, p)| p.0.iter().zip(b.get_pixel(*x, *y).0).any(|(u, v)| u.abs_diff(v) > 2))
        .map(|(x, y, _)| (x, y))
        .collect()
}

#[test]
fn the_viewer_flies_in_a_real_window_and_shows_what_render_renders() {
    let Some(server) = Xvfb::start(&["Xvfb", "xdotool", "xwd"]) else { return };
    let display = server.display.clone();
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dataset = synth_dataset(300, 7);
    let tmp = TempDir::new("viewer");
    let settings = tmp.path().join("trees.toml");
    std::fs::write(&settings, format!("[draw_seeds]\nimpostors = {:?}\n", impostors.display().to_string()))
        .unwrap();

    let [w, h] = WINDOW_PX.map(|v| v.to_string());
    let out = tmp.path().join("view");
    let mut viewer = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"))
        .args(["view", "--dataset", dataset.to_str().unwrap(), "--settings", settings.to_str().unwrap()])
        .args(["--width", &w, "--height", &h, "--no-vsync", "--out", out.to_str().unwrap()])
        .env("DISPLAY", &display)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (send, lines) = mpsc::channel();
    for stream in [
        Box::new(viewer.stdout.take().unwrap()) as Box<dyn std::io::Read + Send>,
        Box::new(viewer.stderr.take().unwrap()),
    ] {
        let send = send.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stream).lines().map_while(Result::ok) {
                eprintln!("  view | {line}");
                let _ = send.send(line);
            }
        });
    }
    let _viewer = Killed(viewer);
    wait_for(&lines, "the window shows its first frame");
    let id = String::from_utf8(x(&display, "xdotool", &["search", "--sync", "--name", "terramp"])).unwrap();
    let id = id.lines().next().unwrap().to_owned();
    x(&display, "xdotool", &["windowfocus", "--sync", &id]);
    // A few frames for the first tiles to stream in.
    std::thread::sleep(Duration::from_secs(3));
    let before = capture(&display, &id);
    assert_eq!(before.dimensions(), (WINDOW_PX[0], WINDOW_PX[1]));

    // Fly: forward for two seconds, then a drag to the right, in the window's lower half.
    x(&display, "xdotool", &["keydown", "w", "sleep", "2", "keyup", "w"]);
    let (mx, my) = (WINDOW_PX[0] / 2, WINDOW_PX[1] * 3 / 4);
    let drag = [mx.to_string(), my.to_string(), (mx + 80).to_string()];
    x(&display, "xdotool", &["mousemove", "--window", &id, &drag[0], &drag[1], "mousedown", "1"]);
    x(&display, "xdotool", &["mousemove", "--window", &id, &drag[2], &drag[1], "sleep", "1", "mouseup", "1"]);
    x(&display, "xdotool", &["key", "F12"]);
    let said = wait_for(&lines, "the same view headless: ");
    let line = said.split("the same view headless: ").nth(1).unwrap().to_owned();
    std::thread::sleep(Duration::from_secs(2));
    let with_overlay = capture(&display, &id);
    x(&display, "xdotool", &["key", "h"]);
    std::thread::sleep(Duration::from_secs(2));
    let window = capture(&display, &id);

    // The same view headless, by the line the screenshot gave.
    let args: Vec<&str> = line.split_whitespace().skip(1).collect();
    let status = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp")).args(&args).status().unwrap();
    assert!(status.success(), "{line}");
    let out_at = args.iter().position(|a| *a == "--out").unwrap() + 1;
    let headless = image::open(args[out_at]).unwrap().to_rgba8();
    let db = psnr(&window, &headless);
    let overlay = changed(&with_overlay, &window);
    let moved = changed(&before, &window).len();
    let colours: std::collections::BTreeSet<[u8; 4]> = window.pixels().map(|p| p.0).collect();
    println!(
        "window against headless: {db:.1} dB; overlay over {} px; {moved} px changed by the flight; {} colours",
        overlay.len(),
        colours.len()
    );
    window.save(tmp.path().join("window.png")).unwrap();
    with_overlay.save(tmp.path().join("with_overlay.png")).unwrap();
    assert!(db >= WINDOW_PSNR_DB, "{db:.1} dB");
    assert!(colours.len() > 1000, "the terrain is drawn: {} colours", colours.len());
    // The overlay: a panel at the top left, bright text on dark.
    let area = (WINDOW_PX[0] * WINDOW_PX[1]) as usize;
    assert!(overlay.len() > area / 20, "the overlay covers {} px", overlay.len());
    let luma = |(x, y): &(u32, u32)| {
        let p = with_overlay.get_pixel(*x, *y).0;
        (u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3
    };
    let dark = overlay.iter().filter(|p| luma(p) < 60).count();
    let bright = overlay.iter().filter(|p| luma(p) > 180).count();
    assert!(
        dark > overlay.len() / 3 && bright > 100,
        "panel {dark} dark, {bright} bright of {}",
        overlay.len()
    );
    assert!(moved > area / 4, "the flight changed {moved} px");
}

/// `terramp view` run as a person would (without a backtrace, without the variables in
/// `unset`, with those in `set`): its standard error, once it has failed cleanly.
fn view_fails(unset: &[&str], set: &[(&str, &str)], args: &[&str]) -> String {
    let mut command = terramp_testkit::command(env!("CARGO_BIN_EXE_terramp"));
    command.arg("view").args(args).env("RUST_BACKTRACE", "0").envs(set.iter().copied());
    for var in unset {
        command.env_remove(var);
    }
    let out = command.output().unwrap();
    let said = String::from_utf8_lossy(&out.stderr).trim().to_owned();
    assert!(!out.status.success() && out.status.code().is_some(), "no clean failure: {said}");
    assert!(!said.contains("panicked"), "{said}");
    said
}

#[test]
fn without_a_display_or_a_dataset_the_viewer_says_so_and_fails() {
    const HEADLESS: [&str; 2] = ["DISPLAY", "WAYLAND_DISPLAY"];
    let dataset = synth_dataset(300, 7);
    let no_display = view_fails(&HEADLESS, &[], &["--dataset", dataset.to_str().unwrap()]);
    assert!(no_display.contains("no display to open a window on (neither DISPLAY"), "{no_display}");
    let missing = view_fails(&[], &[], &["--dataset", "/nonexistent/terramp-dataset"]);
    assert!(missing.contains("cannot open the dataset /nonexistent/terramp-dataset"), "{missing}");

    // The embedded default, not made yet: a missing adapter (none on a backend this system lacks)
    // or display is found before the default is synthesized or its trees baked.
    let fresh = TempDir::new("view-default");
    let at = |name: &str| fresh.path().join(name).to_str().unwrap().to_owned();
    let default =
        ["--default-dataset", &at("default"), "--impostors", &at("impostors"), "--models", &at("m")];
    let no_display = view_fails(&HEADLESS, &[], &default);
    assert!(no_display.contains("no display to open a window on"), "{no_display}");
    let no_adapter = view_fails(&HEADLESS, &[("WGPU_BACKEND", "metal")], &default);
    assert!(no_adapter.contains("terramp view needs a GPU adapter"), "{no_adapter}");
    assert!(no_adapter.contains("GPU adapter found (adapters seen: none)"), "{no_adapter}");
    let made: Vec<_> = std::fs::read_dir(fresh.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(made.is_empty(), "made before failing: {made:?}");
}
