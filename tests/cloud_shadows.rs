//! Cloud shadows (`light`, `[clouds]`) on a small synthetic dataset with the shared models baked:
//! - at the same world point ground and seeds are shaded alike, and as the CPU's field says:
//!   every pixel, of the ground or of a tree, whose point (from the depth buffer) the twin puts
//!   well inside a cloud shows what an overcast sky gives it, and every one it puts well clear of
//!   the clouds shows the cloudless frame, bit for bit;
//! - no clouds (coverage 0, or no depth to them) is the cloudless frame bit for bit, whatever the
//!   other knobs and the time;
//! - they drift: a minute later other pixels are in shadow;
//! - on the Earth (a synthetic dataset placed on nc's State Plane) the first holds too, the layer
//!   falling with the ground.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::camera::Camera;
use terramp::config::{CloudSettings, Settings};
use terramp::frame::Renderer;
use terramp::gpu::layout::CLOUD_EDGE;
use terramp_testkit::audit::Rays;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::{camera, differing_pixels, renderer, settled_colour, small_settings, synth_dataset};

const IMAGE_PX: [u32; 2] = [320, 180];

/// How far from a cloud's edge (noise units, past its penumbra) a point must be to be judged: the
/// twin and the shaders round differently, and a pixel's depth names its point to a few mm.
const MARGIN: f32 = 0.01;

fn settings(impostors: &str) -> Settings {
    let mut s = small_settings(IMAGE_PX[0], IMAGE_PX[1]);
    s.draw_seeds.impostors = impostors.to_owned();
    // Clouds small enough that the view holds many, shading the sun's light entirely.
    s.clouds = CloudSettings { coverage: 0.0, shadow_depth: 1.0, scale_m: 150.0, ..s.clouds };
    s
}

/// The view: `above_m` over the ground, looking 10° down.
fn pose(r: &Renderer, above_m: f64) -> Camera {
    camera::over_fraction(r, [0.45, 0.35], above_m, 20.0, -10.0)
}

/// The flat views' height over the ground, metres.
const ABOVE_M: f64 = 25.0;

/// The settled frame of `r` under `clouds` at the scene's time `time_s`, from `above_m` up.
fn frame(r: &mut Renderer, clouds: CloudSettings, time_s: f64, above_m: f64) -> image::RgbaImage {
    r.settings.clouds = clouds;
    r.set_time_s(time_s);
    let camera = pose(r, above_m);
    settled_colour(r, &camera)
}

/// Pixels judged, per kind (ground, tree) and per side (in a cloud, clear).
#[derive(Debug, Default)]
struct Judged {
    /// [ground, tree][inside, clear]
    count: [[u32; 2]; 2],
    /// Pixels not showing what their side says, same indices.
    wrong: [[u32; 2]; 2],
}

#[test]
fn ground_and_seeds_are_shaded_alike_where_the_field_says() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    shaded_alike(impostors.to_str().unwrap(), &|s| renderer(&dir, s), [ABOVE_M, 150.0]);
}

/// The same on the Earth (a synthetic dataset 9 km across placed on nc's State Plane, seen from
/// 400 m up across most of it), where the layer falls with the ground: 0.5 m 2.5 km away, 6 m at
/// the far edge.
#[test]
fn on_the_earth_ground_and_seeds_are_shaded_alike_where_the_field_says() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let make = |s| Renderer::new(terramp_testkit::gpu(), synth_on_nc(300, 30.0, 7), s).unwrap();
    // Clouds 25 m across, so that the fall moves the far ground's lookup across many of them.
    shaded_alike(impostors.to_str().unwrap(), &make, [400.0, 25.0]);
}

/// Renders a view from `above_m` under half cover, overcast and clear, of clouds `scale_m` across,
/// with renderers `make` makes, and checks every pixel the twin puts well inside or well clear of
/// a cloud.
fn shaded_alike(impostors: &str, make: &dyn Fn(Settings) -> Renderer, [above_m, scale_m]: [f64; 2]) {
    let mut base = settings(impostors);
    base.clouds.scale_m = scale_m;
    let half = CloudSettings { coverage: 0.5, ..base.clouds.clone() };
    let overcast = CloudSettings { coverage: 1.0, ..base.clouds.clone() };
    let ground = frame(&mut make(settings("")), half.clone(), 0.0, above_m);
    let mut r = make(base.clone());
    let clear = frame(&mut r, base.clouds.clone(), 0.0, above_m);
    let grey = frame(&mut r, overcast, 0.0, above_m);
    let shaded = frame(&mut r, half, 0.0, above_m);
    let clouds = r.last_clouds().unwrap();
    let depth = r.read_depth().unwrap();
    let camera = pose(&r, above_m);
    let rays = Rays::new(&r, &camera);

    let threshold = clouds.field[3];
    let mut judged = Judged::default();
    for y in 0..IMAGE_PX[1] {
        for x in 0..IMAGE_PX[0] {
            let d = depth[(y * IMAGE_PX[0] + x) as usize];
            if d <= 0.0 {
                continue;
            }
            let rel = rays.point_rel(x, y, d, r.settings.render.near_m).as_vec3().to_array();
            let density = clouds.density_at(rel);
            let side = if density > threshold + CLOUD_EDGE + MARGIN {
                0
            } else if density < threshold - CLOUD_EDGE - MARGIN {
                1
            } else {
                continue;
            };
            // A tree's pixel: the trees change it from the bare ground under the same clouds.
            let kind = usize::from(shaded.get_pixel(x, y) != ground.get_pixel(x, y));
            let expected = if side == 0 { &grey } else { &clear };
            judged.count[kind][side] += 1;
            judged.wrong[kind][side] += u32::from(shaded.get_pixel(x, y) != expected.get_pixel(x, y));
        }
    }
    println!("{judged:?} (ground, tree) × (in a cloud, clear)");
    println!("the clouds darkened {} of {} pixels", differing_pixels(&clear, &shaded), clear.len() / 4);
    for kind in 0..2 {
        for side in 0..2 {
            assert!(judged.count[kind][side] >= 100, "too few pixels to judge: {judged:?}");
        }
    }
    assert_eq!(judged.wrong, [[0; 2]; 2], "pixels shaded otherwise than the field says: {judged:?}");
    // The overcast frame is darker than the clear one wherever the sun lights anything.
    let darker = clear.pixels().zip(grey.pixels()).filter(|(c, g)| g[0] < c[0] || g[1] < c[1]).count();
    assert!(darker > clear.len() / 8, "overcast darkened only {darker} of {} pixels", clear.len() / 4);
}

#[test]
fn no_clouds_is_the_cloudless_frame_bit_for_bit_and_clouds_drift() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    let base = settings(impostors.to_str().unwrap());
    let mut r = renderer(&dir, base.clone());
    let cloudless = frame(&mut r, base.clouds.clone(), 0.0, ABOVE_M);
    let still = CloudSettings { scale_m: 900.0, speed_m_s: 40.0, from_deg: 12.0, ..base.clouds.clone() };
    let no_depth = CloudSettings { coverage: 0.7, shadow_depth: 0.0, ..base.clouds.clone() };
    assert_eq!(
        differing_pixels(&cloudless, &frame(&mut r, still, 321.0, ABOVE_M)),
        0,
        "coverage 0 changed the frame"
    );
    assert_eq!(
        differing_pixels(&cloudless, &frame(&mut r, no_depth, 5.0, ABOVE_M)),
        0,
        "depth 0 changed the frame"
    );

    let cloudy = CloudSettings { coverage: 0.4, speed_m_s: 5.0, ..base.clouds.clone() };
    let now = frame(&mut r, cloudy.clone(), 0.0, ABOVE_M);
    let later = frame(&mut r, cloudy.clone(), 60.0, ABOVE_M);
    let again = frame(&mut r, cloudy, 0.0, ABOVE_M);
    let (shaded, moved) = (differing_pixels(&cloudless, &now), differing_pixels(&now, &later));
    println!("clouds shaded {shaded} pixels, a minute later {moved} of them changed");
    assert_eq!(differing_pixels(&now, &again), 0, "the same time shows other clouds");
    assert!(shaded > 2000 && moved > 1000, "clouds hardly shade or move: {shaded}, {moved}");
}
