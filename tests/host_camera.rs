//! A host's camera drawn through every pass: the camera a host's view and projection matrices give
//! (`Camera::from_matrices`), rolled a quarter turn, on a square viewport. Rolling the camera
//! about its view direction turns the image and changes nothing else the passes select (the
//! frustum of a square view turned a quarter is the same frustum), so its frame is the level
//! camera's frame turned a quarter counter-clockwise, up to what is laid out in screen space
//! (dither patterns, the rasteriser's sample positions and tie rules). Turned the other way, the
//! level frame is the control that must fail.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DMat4;
use image::imageops::{rotate90, rotate270};
use terramp::camera::Camera;
use terramp_testkit::{camera, psnr, renderer, small_settings, synth_dataset};

/// The square viewport's side, pixels.
const SIDE: u32 = 256;
/// Least PSNR of the rolled camera's frame against the level frame turned a quarter, dB.
const TURNED_PSNR_DB: f64 = 50.0;
/// Most PSNR of the rolled frame against the level frame turned the wrong way (the control), dB.
const CONTROL_PSNR_DB: f64 = 20.0;
/// Most seeds, as a share of the level view's, that pass 3 may select in one of the two views
/// and not the other: those on the frustum's very edge, where f32 rounds differently.
const SELECTION_DIFFERENCE: f64 = 0.01;

#[test]
fn a_host_camera_rolled_a_quarter_turn_draws_the_level_frame_turned_a_quarter() {
    let dir = synth_dataset(300, 7);
    let mut r = renderer(&dir, small_settings(SIDE, SIDE));
    let level = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
    // The host's matrices: its view turned about the view axis so that the camera's right side
    // points down (view-space x to −y), and terramp's kind of projection.
    let world_from_view =
        level.view_from_world().inverse() * DMat4::from_rotation_z(-std::f64::consts::FRAC_PI_2);
    let clip_from_view = level.clip_from_view(SIDE, SIDE).unwrap();
    let rolled =
        Camera::from_matrices(level.position_m, world_from_view.inverse(), clip_from_view, [SIDE, SIDE])
            .unwrap();
    assert!((rolled.roll_deg - 90.0).abs() < 1e-9, "{rolled:?}");
    assert!(
        (rolled.yaw_deg - level.yaw_deg).abs() < 1e-9 && (rolled.pitch_deg - level.pitch_deg).abs() < 1e-9
    );

    let mut frame = |camera: &Camera| {
        r.render_resolved(camera).unwrap();
        let report = r.render(camera).unwrap();
        (r.read_colour().unwrap(), report.seeds.unwrap().counters.selected)
    };
    let (level_frame, level_selected) = frame(&level);
    let (rolled_frame, rolled_selected) = frame(&rolled);
    let turned = psnr(&rolled_frame, &rotate270(&level_frame));
    let control = psnr(&rolled_frame, &rotate90(&level_frame));
    println!(
        "seeds selected: level {level_selected}, rolled {rolled_selected}; rolled against the level frame turned \
         a quarter counter-clockwise {turned:.2} dB, clockwise (the control) {control:.2} dB"
    );
    assert!(level_selected > 100, "the view must draw trees: {level_selected}");
    let difference = f64::from(level_selected.abs_diff(rolled_selected)) / f64::from(level_selected);
    assert!(difference <= SELECTION_DIFFERENCE, "{level_selected} against {rolled_selected}");
    assert!(turned >= TURNED_PSNR_DB, "{turned} dB");
    assert!(control <= CONTROL_PSNR_DB, "the control passes: {control} dB");
}
