//! The wind (`seeds::wind`) on a small synthetic dataset with the shared models baked:
//! - still air is still: at speed 0 the frame is the same, bit for bit, whatever the wind's
//!   direction and time (the shaders take the path they took before the wind existed);
//! - a frame number always shows the same sway: one wind time rendered in two renderers, and again
//!   after other times in the same one, gives the same frame bit for bit; the next frame differs;
//! - only seeds move: outside the seeds' bounds (found from pass 3's records and the camera, not
//!   from the frames compared) the still frame is the bare ground and the windy frame the still
//!   one, and the trees do move; drifting cloud shadows, which are not seeds, are seen there;
//! - pass 3 grows its bounds with the wind: every seed still air selects is selected in a storm
//!   too, and some more at the view's edges (GPU == twin with wind is `tests/seed_select.rs`).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::HashSet;

use glam::{DVec3, DVec4};
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp::gpu::layout::SpeciesLod;
use terramp::seeds::wind::{Wind, bend_of};
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

/// A settled frame, and the pixels its seeds may cover.
struct Frame {
    image: image::RgbaImage,
    /// Per pixel, row by row: whether it lies inside some seed's bounds (`seed_bounds`).
    seeds: Vec<bool>,
}

/// The settled frame of `r` at the test's pose and wind time `time_s`.
fn frame_at(r: &mut Renderer, time_s: f64) -> Frame {
    r.set_time_s(time_s);
    let camera = pose(r);
    let image = settled_colour(r, &camera);
    let seeds = seed_bounds(r, &camera);
    Frame { image, seeds }
}

/// The pixels that the seeds pass 3 selected in `r`'s last frame may cover, wind included, found
/// from their records and the camera alone (not from any frame's colours): a pixel is inside when
/// the ray through its centre passes within a seed's bounding sphere, as pass 3 bounds it
/// (centred half-way up the sunk seed, `radius_per_height` of its height plus, for a plant, the
/// wind's reach, `seeds::wind`), then grown by a pixel all round. The rasteriser covers a pixel
/// when its centre's ray meets a triangle, so a seed drawn inside its sphere covers no pixel
/// outside; the pixel of growth is for the f32 rounding of the vertices on the sphere's rim.
fn seed_bounds(r: &Renderer, camera: &Camera) -> Vec<bool> {
    let [w, h] = IMAGE_PX;
    let (records, _) = r.read_seeds().unwrap().unwrap();
    let table = r.class_table().unwrap();
    let reach_per_height = Wind::new(&r.settings.wind).reach_per_height();
    let clip_from_world = camera.clip_from_view(w, h).unwrap() * camera.view_from_world();
    let world_from_clip = clip_from_world.inverse();
    // Each pixel centre's ray (camera-relative world, unit), through the near plane (z 1).
    let rays: Vec<DVec3> = (0..w * h)
        .map(|i| {
            let (x, y) = (f64::from(i % w) + 0.5, f64::from(i / w) + 0.5);
            let ndc = DVec4::new(2.0 * x / f64::from(w) - 1.0, 1.0 - 2.0 * y / f64::from(h), 1.0, 1.0);
            let p = world_from_clip * ndc;
            (p.truncate() / p.w).normalize()
        })
        .collect();
    let mut inside = vec![false; (w * h) as usize];
    for record in &records {
        let species = &table.species[SpeciesLod::unpack(record.species_lod).species as usize];
        let height_m = f64::from(record.height_m);
        let sway_m = height_m * f64::from(bend_of(species.kind)) * reach_per_height;
        let radius_m = height_m * f64::from(species.radius_per_height) + sway_m;
        let centre = DVec3::from(record.position_rel_m.map(f64::from)) + DVec3::Z * 0.5 * height_m;
        // The pixels to look at: those of the box around the sphere, or all if it reaches the
        // near plane.
        let sign = |bit: usize| if bit == 0 { -radius_m } else { radius_m };
        let corners = (0..8usize).map(|k| {
            let corner = centre + DVec3::new(sign(k & 1), sign(k >> 1 & 1), sign(k >> 2));
            clip_from_world * corner.extend(1.0)
        });
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut whole_view = false;
        for c in corners {
            if c.w <= camera.near_m {
                whole_view = true;
                break;
            }
            let px = [(c.x / c.w + 1.0) * 0.5 * f64::from(w), (1.0 - c.y / c.w) * 0.5 * f64::from(h)];
            for k in 0..2 {
                lo[k] = lo[k].min(px[k]);
                hi[k] = hi[k].max(px[k]);
            }
        }
        let span = |k: usize, size: u32| {
            if whole_view {
                0..size
            } else {
                (lo[k].floor().max(0.0) as u32)..(hi[k].ceil().min(f64::from(size)).max(0.0) as u32)
            }
        };
        for y in span(1, h) {
            for x in span(0, w) {
                let i = (y * w + x) as usize;
                let along = centre.dot(rays[i]);
                let off_sq = centre.length_squared() - along * along;
                inside[i] |= off_sq <= radius_m * radius_m && (along > 0.0 || centre.length() <= radius_m);
            }
        }
    }
    let at = |x: i64, y: i64| {
        x >= 0 && y >= 0 && x < i64::from(w) && y < i64::from(h) && inside[(y * i64::from(w) + x) as usize]
    };
    (0..i64::from(w * h))
        .map(|i| {
            let (x, y) = (i % i64::from(w), i / i64::from(w));
            (-1..=1).any(|dy| (-1..=1).any(|dx| at(x + dx, y + dy)))
        })
        .collect()
}

/// Outside the seeds' bounds of either frame, how many pixels there are and how many of them
/// differ between `a` and `b`.
fn changed_outside(a: &Frame, b: &Frame) -> (u32, u32) {
    let (mut open, mut changed) = (0u32, 0u32);
    for (i, (p, q)) in a.image.pixels().zip(b.image.pixels()).enumerate() {
        if !a.seeds[i] && !b.seeds[i] {
            open += 1;
            changed += u32::from(p != q);
        }
    }
    (open, changed)
}

#[test]
fn still_air_is_still_and_a_frame_number_always_shows_the_same_sway() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let impostors = impostors.to_str().unwrap();
    let dir = synth_dataset(300, 7);
    let ground = frame_at(&mut renderer(&dir, settings("", 0.0, 270.0)), 0.0);
    let still = frame_at(&mut renderer(&dir, settings(impostors, 0.0, 270.0)), 0.0);
    let still_later = frame_at(&mut renderer(&dir, settings(impostors, 0.0, 45.0)), 123.4);
    assert_eq!(differing_pixels(&still.image, &still_later.image), 0, "still air moved something");

    let windy = settings(impostors, 12.0, 250.0);
    let frame_7 = windy.wind.time_of_frame_s(7);
    let frame_8 = windy.wind.time_of_frame_s(8);
    let mut a = renderer(&dir, windy.clone());
    let a7 = frame_at(&mut a, frame_7);
    let a8 = frame_at(&mut a, frame_8);
    let a7_again = frame_at(&mut a, frame_7);
    let b7 = frame_at(&mut renderer(&dir, windy.clone()), frame_7);
    assert_eq!(differing_pixels(&a7.image, &a7_again.image), 0, "frame 7 drawn again after frame 8 differs");
    assert_eq!(differing_pixels(&a7.image, &b7.image), 0, "frame 7 differs between two renderers");
    let (swayed, stepped) =
        (differing_pixels(&still.image, &a7.image), differing_pixels(&a7.image, &a8.image));
    println!("the wind changed {swayed} pixels of the still frame, one frame later {stepped} changed");
    assert!(swayed > 200 && stepped > 20, "the trees hardly move: {swayed}, {stepped}");

    // The seeds' bounds hold every seed drawn: without them the frame is the bare ground.
    let (open, changed) = changed_outside(&ground, &still);
    println!("{open} pixels outside every seed's bounds, {changed} of them differ from the bare ground");
    assert!(open > 1000, "only {open} pixels outside the seeds' bounds: a weak test");
    assert_eq!(changed, 0, "the trees drew {changed} pixels outside their bounds");
    // Outside every seed's bounds, still or windy, the windy frame is the still one: the wind
    // bends seeds, nothing else.
    let (open, changed) = changed_outside(&still, &a7);
    println!(
        "{open} pixels outside the seeds' bounds, still or windy, {changed} of them changed in the wind"
    );
    assert!(open > 1000, "only {open} pixels outside the seeds' bounds: a weak test");
    assert_eq!(changed, 0, "the wind changed {changed} pixels outside the seeds' bounds");

    // The control: something that is not a plant moving with the scene's time, the clouds'
    // shadows drifting over the ground for a minute (720 m), is seen outside the bounds.
    let mut clouded = windy;
    clouded.clouds.coverage = 0.5;
    let mut c = renderer(&dir, clouded);
    let (c7, c_later) = (frame_at(&mut c, frame_7), frame_at(&mut c, frame_7 + 60.0));
    let (open, drifted) = changed_outside(&c7, &c_later);
    println!(
        "control: a minute of drifting clouds changed {drifted} of {open} pixels outside the seeds' bounds"
    );
    assert!(drifted > 100, "the clouds' drift went unseen outside the seeds' bounds: {drifted} pixels");
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
