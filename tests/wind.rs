//! The wind (`seeds::wind`) on a small synthetic dataset with the shared models baked:
//! - still air is still: at speed 0 the frame is the same, bit for bit, whatever the wind's
//!   direction and time (the shaders take the path they took before the wind existed);
//! - a frame number always shows the same sway: one wind time rendered in two renderers, and again
//!   after other times in the same one, gives the same frame bit for bit; the next frame differs;
//! - only plants move: away from the trees a windy frame is the still one, and the trees do move;
//! - pass 3 grows its bounds with the wind: every seed still air selects is selected in a storm
//!   too, and some more at the view's edges (GPU == twin with wind is `tests/seed_select.rs`).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::HashSet;

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp_testkit::{camera, differing_pixels, renderer, settled_colour, small_settings, synth_dataset};

const IMAGE_PX: [u32; 2] = [320, 180];

fn settings(impostors: &str, speed_m_s: f64, from_deg: f64) -> Settings {
    let mut s = small_settings(IMAGE_PX[0], IMAGE_PX[1]);
    s.draw_seeds.impostors = impostors.to_owned();
    s.wind.speed_m_s = speed_m_s;
    s.wind.from_deg = from_deg;
    s
}

fn pose(r: &Renderer) -> Camera {
    camera::over_fraction(r, [0.45, 0.35], 25.0, 20.0, -10.0)
}

/// The settled frame of `r` at the test's pose and wind time `time_s`.
fn frame_at(r: &mut Renderer, time_s: f64) -> image::RgbaImage {
    r.set_time_s(time_s);
    let camera = pose(r);
    settled_colour(r, &camera)
}

#[test]
fn still_air_is_still_and_a_frame_number_always_shows_the_same_sway() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let impostors = impostors.to_str().unwrap();
    let dir = synth_dataset(300, 7);
    let ground = frame_at(&mut renderer(&dir, settings("", 0.0, 270.0)), 0.0);
    let still = frame_at(&mut renderer(&dir, settings(impostors, 0.0, 270.0)), 0.0);
    let still_later = frame_at(&mut renderer(&dir, settings(impostors, 0.0, 45.0)), 123.4);
    assert_eq!(differing_pixels(&still, &still_later), 0, "still air moved something");

    let windy = settings(impostors, 12.0, 250.0);
    let frame_7 = windy.wind.time_of_frame_s(7);
    let frame_8 = windy.wind.time_of_frame_s(8);
    let mut a = renderer(&dir, windy.clone());
    let a7 = frame_at(&mut a, frame_7);
    let a8 = frame_at(&mut a, frame_8);
    let a7_again = frame_at(&mut a, frame_7);
    let b7 = frame_at(&mut renderer(&dir, windy), frame_7);
    assert_eq!(differing_pixels(&a7, &a7_again), 0, "frame 7 drawn again after frame 8 differs");
    assert_eq!(differing_pixels(&a7, &b7), 0, "frame 7 differs between two renderers");
    let (swayed, stepped) = (differing_pixels(&still, &a7), differing_pixels(&a7, &a8));
    println!("the wind changed {swayed} pixels of the still frame, one frame later {stepped} changed");
    assert!(swayed > 200 && stepped > 20, "the trees hardly move: {swayed}, {stepped}");

    // Away from the trees (3 pixels from any pixel the trees touch, still or swaying), the windy
    // frame is the still one: the wind bends seeds, nothing else.
    let (w, h) = (IMAGE_PX[0] as i64, IMAGE_PX[1] as i64);
    let tree = |x: i64, y: i64| {
        x >= 0 && y >= 0 && x < w && y < h && {
            let g = ground.get_pixel(x as u32, y as u32);
            still.get_pixel(x as u32, y as u32) != g || a7.get_pixel(x as u32, y as u32) != g
        }
    };
    let near_tree = |x: i64, y: i64| (-3..=3).any(|dy| (-3..=3).any(|dx| tree(x + dx, y + dy)));
    let (mut open, mut changed) = (0u32, 0u32);
    for y in 0..h {
        for x in 0..w {
            if !near_tree(x, y) {
                open += 1;
                changed += u32::from(still.get_pixel(x as u32, y as u32) != a7.get_pixel(x as u32, y as u32));
            }
        }
    }
    println!("{open} pixels away from the trees, {changed} of them changed");
    assert!(open > 1000, "only {open} pixels away from the trees: a weak test");
    assert_eq!(changed, 0, "the wind changed {changed} pixels away from the trees");
}

#[test]
fn a_storm_keeps_every_seed_still_air_keeps() {
    let dir = synth_dataset(1024, 7);
    let selected = |speed_m_s: f64| {
        let mut r = renderer(&dir, settings("", speed_m_s, 300.0));
        let camera = camera::over_fraction(&r, [0.5, 0.5], 30.0, 60.0, -15.0);
        r.render_resolved(&camera).unwrap();
        let (records, _) = r.read_seeds().unwrap().unwrap();
        records.iter().map(|s| (s.address, s.rank)).collect::<HashSet<_>>()
    };
    let (still, storm) = (selected(0.0), selected(40.0));
    let gained = storm.difference(&still).count();
    println!("still air selects {} seeds, a storm {} ({gained} more)", still.len(), storm.len());
    assert!(!still.is_empty());
    assert!(still.is_subset(&storm), "a storm lost {} seeds", still.difference(&storm).count());
    assert!(gained > 0, "the storm's sway grew no seed's bounds into the view");
}
