//! The air on what the frame draws (`shaders/shared/air.wgsl`): the sky-irradiance table and the
//! daylight balance on the GPU against the twin, the irradiance against the brute-force model,
//! and a frame seen through the air against the same frame without it, pixel by pixel through
//! the twin's volume — the ground and the seeds alike, each at its own depth.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use terramp::atmosphere::brute::Brute;
use terramp::config::Settings;
use terramp::light::sun_dir;
use terramp::passes::atmosphere::frame::{SkyView, atmosphere_uniforms};
use terramp::passes::atmosphere::gpu::AtmospherePass;
use terramp::photo::colour::luminance;
use terramp::reference::atmosphere::light::through_air;
use terramp::reference::atmosphere::{Model, Tables, tables};
use terramp::synth::SynthParams;
use terramp::texcell::pyramid::{decode_srgb, encode_srgb};

/// A frame's light (`Renderer::read_light`), pixel by pixel.
type Light = Vec<[f32; 3]>;
use terramp_testkit::camera::over_fraction;
use terramp_testkit::{gpu, renderer, small_settings, synth_dataset_with};

/// The GPU's irradiance texels and daylight balance against the twin's, relative.
const TABLE_OFF: f32 = 1e-3;
/// The irradiance table's sky light on level ground at sea level against the brute force's,
/// relative, per channel (the table gathers the tables' sky from 64 directions; the truth
/// integrates its own sky over 256).
const IRRADIANCE_OFF: f64 = 0.05;
/// A frame's light through the air against the twin's air over the same frame's light without
/// it, in levels of 8-bit sRGB: most pixels within `AIR_LEVELS`...
const AIR_LEVELS: i32 = 2;
/// ... all but this share of them (pixels where a silhouette's depth and colour come from
/// different surfaces, whose air the per-pixel depth cannot tell)...
const AIR_OUTLIERS: f64 = 0.005;
/// ... and the air must change the ground beyond `FAR_M` by at least this mean, levels, for the
/// check to mean anything.
const AIR_MIN_CHANGE: f64 = 3.0;
/// The far ground of that check, metres from the camera.
const FAR_M: f32 = 1000.0;
/// From 100 km, the share of the ground's contrast the frame keeps against the brute force's
/// transmittance along each pixel's ray, relative, per channel (the bound).
const CONTRAST_OFF: f64 = 0.05;

/// The sun `elevation_deg` above the horizon, along +x.
fn sun(elevation_deg: f64) -> DVec3 {
    let e = elevation_deg.to_radians();
    DVec3::new(e.cos(), 0.0, e.sin())
}

fn still(altitude_m: f64, sun_elevation_deg: f64) -> SkyView {
    SkyView {
        view_world_from_clip: glam::DMat4::IDENTITY,
        up: DVec3::Z,
        sun_dir: sun(sun_elevation_deg),
        altitude_m,
    }
}

#[test]
fn the_gpu_makes_the_twins_sky_irradiance_and_daylight_balance() {
    let gpu = gpu();
    let s = Settings::default().atmosphere;
    let pass = AtmospherePass::new(&gpu, &s);
    let [_, _, _, irradiance] = pass.read_back(&gpu).unwrap();
    let daylight = pass.read_back_daylight(&gpu).unwrap();
    let u = atmosphere_uniforms(&s, &still(0.0, 45.0));
    let (transmittance, multiple, _) = tables(&u);
    let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
    let twin_irradiance = twin.irradiance_lut(s.irradiance_lut);
    let brightest = twin_irradiance.texels.iter().map(|t| t[2]).fold(0.0f32, f32::max);
    // Texels under 1 % of the brightest (the top of the air, the night side) by their absolute
    // error: there f32's rounding of near-vacuum sums shows, 10⁻⁵ of the brightest at most.
    let off = twin_irradiance
        .texels
        .iter()
        .zip(&irradiance)
        .flat_map(|(t, g)| (0..3).map(move |c| (t[c] - g[c]).abs() / t[c].max(1e-2 * brightest)))
        .fold(0.0f32, f32::max);
    assert!(off < TABLE_OFF, "the irradiance table is off the twin's by {off:e}");
    let twin_daylight = twin.daylight_balance(&twin_irradiance);
    for c in 0..3 {
        let off = (daylight[c] / twin_daylight[c] - 1.0).abs();
        assert!(off < TABLE_OFF, "daylight balance {daylight:?} against the twin's {twin_daylight}");
    }
    // Daylight is near white (its balance's channels lie 1.13 apart on lavapipe, blue the most
    // corrected), and level white ground under the sun at 45° then shows white.
    let spread = twin_daylight.max_element() / twin_daylight.min_element();
    println!("daylight balance {twin_daylight}, its channels {spread:.3} apart");
    assert!(spread < 1.5, "daylight's colour {twin_daylight}");
}

#[test]
fn the_sky_irradiance_is_the_brute_force_s() {
    // Level ground at sea level, the sun at 60°, 20° and 5°: the table's sky light against the
    // brute force's sky integrated over 16 × 16 directions of the upper half (even in azimuth and
    // in the zenith cosine), 64 paths per channel each.
    let s = Settings::default().atmosphere;
    let brute = Brute::new(s.air);
    let side = 16usize;
    for sun_deg in [60.0, 20.0, 5.0] {
        let u = atmosphere_uniforms(&s, &still(0.0, sun_deg));
        let (transmittance, multiple, _) = tables(&u);
        let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
        let irradiance = twin.irradiance_lut(s.irradiance_lut);
        let table = twin.light_at(&irradiance, Vec3::ZERO).sky.as_dvec3();
        let origin = DVec3::new(0.0, 0.0, f64::from(u.radii[2]));
        let gathered: DVec3 = (0..side * side)
            .into_par_iter()
            .map(|i| {
                let azimuth = std::f64::consts::TAU * ((i % side) as f64 + 0.5) / side as f64;
                let mu = ((i / side) as f64 + 0.5) / side as f64;
                let ring = (1.0 - mu * mu).sqrt();
                let dir = DVec3::new(ring * azimuth.cos(), ring * azimuth.sin(), mu);
                DVec3::from(brute.sky(origin, dir, sun(sun_deg), 64, i as u64 * 131 + 7).radiance()) * mu
            })
            .sum();
        let truth = gathered * std::f64::consts::TAU / (side * side) as f64;
        let off = (table / truth - 1.0).abs();
        println!("sun {sun_deg}°: table {table:.5}, truth {truth:.5}, off {off:.4}");
        assert!(off.max_element() < IRRADIANCE_OFF, "sun {sun_deg}°: table {table} against {truth}");
        assert!(luminance(truth.to_array()) > 0.0);
    }
}

/// What a view's check found, per part (ground, seeds): pixels, those off the twin's air by more
/// than `AIR_LEVELS`, the worst; and the far ground (beyond `FAR_M`): pixels, the air's mean
/// change, levels.
struct AirCheck {
    parts: [(u32, u32, i32); 2],
    far: (u32, f64),
}

/// The light of a frame of a 9 km synthetic dataset (with nc's trees) from `pose` (fraction
/// across, along, metres above the ground, yaw, pitch) without aerial perspective, taken through
/// the twin's air at each pixel's depth, against the frame's with it.
fn check_air(pose: ([f64; 2], f64, f64, f64)) -> AirCheck {
    let impostors = terramp_testkit::nc_impostors().unwrap();
    let dataset =
        synth_dataset_with(&SynthParams { size: 300, seed: 7, spacing_m: 30.0, ..Default::default() });
    let (width, height) = (240, 135);
    let frame = |aerial: bool, seeds: bool| {
        let mut s = small_settings(width, height);
        s.atmosphere.aerial_perspective = aerial;
        s.draw_seeds.samples = 1;
        s.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
        if !seeds {
            s.seeds.density_scale = 0.0;
        }
        let mut r = renderer(&dataset, s.clone());
        let (at, above_m, yaw_deg, pitch_deg) = pose;
        let camera = over_fraction(&r, at, above_m, yaw_deg, pitch_deg);
        r.render_resolved(&camera).unwrap();
        (r.read_light().unwrap(), r.read_depth().unwrap(), camera, s)
    };
    let (bare, ..) = frame(false, false);
    let (clear, _, _, _) = frame(false, true);
    let (hazed, depth, camera, s) = frame(true, true);
    let clip = camera.clip_from_view(width, height).unwrap() * camera.view_from_world();
    let sky = SkyView {
        view_world_from_clip: clip.inverse(),
        up: DVec3::Z,
        sun_dir: sun_dir(&s.render),
        altitude_m: camera.position_m.z,
    };
    let u = atmosphere_uniforms(&s.atmosphere, &sky);
    let (transmittance, multiple, _) = tables(&u);
    let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
    let daylight = twin.daylight_balance(&twin.irradiance_lut(s.atmosphere.irradiance_lut));
    let volume = twin.aerial_volume();
    let mut check = AirCheck { parts: [(0, 0, 0); 2], far: (0, 0.0) };
    let code = |light: [f32; 3]| light.map(encode_srgb);
    for (i, (&seen, &lit)) in hazed.iter().zip(&clear).enumerate() {
        let d = depth[i];
        if d == 0.0 {
            continue;
        }
        let (x, y) = (i as u32 % width, i as u32 / width);
        let ndc = glam::DVec4::new(
            (f64::from(x) + 0.5) / f64::from(width) * 2.0 - 1.0,
            1.0 - (f64::from(y) + 0.5) / f64::from(height) * 2.0,
            f64::from(d),
            1.0,
        );
        let point = clip.inverse() * ndc;
        let rel_m = (point.truncate() / point.w).as_vec3();
        let lit_pi = Vec3::from_array(lit) / daylight;
        let expected = code(through_air(&twin, &volume, daylight, lit_pi, rel_m).to_array());
        let (shown, lit) = (code(seen), code(lit));
        let seed = code(bare[i]) != lit;
        let part = &mut check.parts[usize::from(seed)];
        let off = (0..3).map(|c| (i32::from(shown[c]) - i32::from(expected[c])).abs()).max().unwrap();
        part.0 += 1;
        part.1 += u32::from(off > AIR_LEVELS);
        part.2 = part.2.max(off);
        if !seed && rel_m.length() > FAR_M {
            let change = (0..3).map(|c| (i32::from(shown[c]) - i32::from(lit[c])).abs()).sum::<i32>();
            check.far = (check.far.0 + 1, check.far.1 + f64::from(change) / 3.0);
        }
    }
    let (far, change) = check.far;
    check.far.1 = change / f64::from(far.max(1));
    println!("the ground beyond {FAR_M} m: {far} pixels, the air changes them by {:.1} levels", check.far.1);
    for (name, (pixels, outliers, worst)) in ["ground", "seeds"].into_iter().zip(check.parts) {
        println!("{name}: {pixels} pixels, {outliers} off by more than {AIR_LEVELS} (worst {worst})");
    }
    check
}

/// `check`'s parts each within `AIR_LEVELS` but for `AIR_OUTLIERS` of their pixels, those of the
/// parts named in `shown` at least 500, and the far ground changed by the air.
fn assert_air(check: &AirCheck, shown: &[&str]) {
    assert!(
        check.far.0 > 500 && check.far.1 > AIR_MIN_CHANGE,
        "the air changes the far ground ({} pixels) by only {:.1} levels",
        check.far.0,
        check.far.1
    );
    for (name, &(pixels, outliers, worst)) in ["ground", "seeds"].into_iter().zip(&check.parts) {
        assert!(!shown.contains(&name) || pixels > 500, "{name}: {pixels} pixels");
        assert!(
            f64::from(outliers) <= AIR_OUTLIERS * f64::from(pixels),
            "{name}: {outliers} of {pixels} pixels off the twin's air by more than {AIR_LEVELS} levels (worst {worst})"
        );
    }
}

#[test]
fn the_frame_is_its_lit_colours_seen_through_the_air_ground_and_seeds_alike() {
    // From 40 m over the dataset's southern edge, looking north 3° down: ground from a few metres
    // to the far edge, seeds in the foreground; the air from the volume.
    if terramp_testkit::nc_impostors().is_none() {
        return;
    }
    assert_air(&check_air(([0.5, 0.02], 40.0, 0.0, -3.0)), &["ground", "seeds"]);
}

#[test]
fn from_high_up_the_air_is_marched_per_pixel() {
    // From 40 km straight down over the dataset's centre: the air marched per pixel
    // (above `SKY_MARCHED_ABOVE_KM`), the whole column of it between the camera and the ground.
    if terramp_testkit::nc_impostors().is_none() {
        return;
    }
    assert_air(&check_air(([0.5, 0.5], 40_000.0, 0.0, -90.0)), &["ground"]);
}

#[test]
fn the_ground_is_lit_by_the_sun_through_the_air_red_at_dusk_and_dark_at_night() {
    // The same ground under the sun at 40°, 3° and −20°: at 3° the sun's light has crossed ~20×
    // more air and the blue has left it; at −20° neither sun nor sky lights it.
    let dataset =
        synth_dataset_with(&SynthParams { size: 300, seed: 7, spacing_m: 30.0, ..Default::default() });
    let mean_rgb = |elevation_deg: f64| {
        let mut s = small_settings(96, 64);
        s.seeds.density_scale = 0.0;
        s.atmosphere.aerial_perspective = false;
        s.render.sun_elevation_deg = elevation_deg;
        let mut r = renderer(&dataset, s);
        let camera = over_fraction(&r, [0.5, 0.5], 400.0, 0.0, -60.0);
        r.render_resolved(&camera).unwrap();
        let (light, depth) = (r.read_light().unwrap(), r.read_depth().unwrap());
        let ground: Vec<_> = light.iter().zip(&depth).filter(|(_, d)| **d != 0.0).map(|(p, _)| p).collect();
        assert!(ground.len() > 96 * 64 / 2, "{} ground pixels", ground.len());
        let mut sum = [0.0f64; 3];
        for p in &ground {
            for c in 0..3 {
                sum[c] += f64::from(p[c]);
            }
        }
        sum.map(|v| v / ground.len() as f64)
    };
    let (noon, dusk, night) = (mean_rgb(40.0), mean_rgb(3.0), mean_rgb(-20.0));
    println!("40°: {noon:?}, 3°: {dusk:?}, −20°: {night:?}");
    assert!(luminance(dusk) < 0.1 * luminance(noon), "dusk {dusk:?} against noon {noon:?}");
    assert!(night.iter().all(|c| *c < f64::from(decode_srgb(2))), "the ground is lit at night: {night:?}");
    // The sun's light that reaches the ground at 3° has lost its blue: the light at a point.
    let s = Settings::default().atmosphere;
    let sun_light = |elevation_deg: f64| {
        let u = atmosphere_uniforms(&s, &still(2.0, elevation_deg));
        let (transmittance, multiple, _) = tables(&u);
        let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
        twin.light_at(&twin.irradiance_lut(s.irradiance_lut), Vec3::ZERO).sun
    };
    let (high, low) = (sun_light(40.0), sun_light(3.0));
    println!("the sun's light on the ground at 40°: {high}, at 3°: {low}");
    assert!(low.x / low.z > 3.0 * (high.x / high.z), "at 3° {low} is not redder than at 40° {high}");
}

#[test]
fn from_100_km_a_relief_keeps_the_contrast_the_brute_force_transmittance_gives_it() {
    // A 90 km synthetic dataset straight down from 100 km (the air's top): the frame with aerial
    // perspective against the one without, their neighbouring pixels' differences in linear
    // light per channel (the in-scattering, smooth across the view, drops out of them): the
    // least-squares slope of one on the other is the share of the ground's contrast the air lets
    // through, and the brute-force model's transmittance along each pixel's ray says what it is.
    let dataset =
        synth_dataset_with(&SynthParams { size: 300, seed: 7, spacing_m: 300.0, ..Default::default() });
    let (width, height) = (192, 108);
    let frame = |aerial: bool| {
        let mut s = small_settings(width, height);
        s.seeds.density_scale = 0.0;
        s.atmosphere.aerial_perspective = aerial;
        let mut r = renderer(&dataset, s.clone());
        let camera = over_fraction(&r, [0.5, 0.5], 0.0, 0.0, -90.0);
        // 100 km above the datum, wherever the ground below is.
        let camera = terramp::camera::Camera {
            position_m: DVec3::new(camera.position_m.x, camera.position_m.y, 100_000.0),
            ..camera
        };
        r.render_resolved(&camera).unwrap();
        (r.read_light().unwrap(), r.read_depth().unwrap(), camera, s)
    };
    let (clear, _, _, _) = frame(false);
    let (seen, depth, camera, s) = frame(true);
    let clip = camera.clip_from_view(width, height).unwrap() * camera.view_from_world();
    let brute = Brute::new(s.atmosphere.air);
    let camera_km = DVec3::new(0.0, 0.0, s.atmosphere.air.bottom_radius_km + camera.position_m.z / 1000.0);
    let ground = |x: u32, y: u32| -> Option<DVec3> {
        let d = depth[(y * width + x) as usize];
        (d != 0.0).then(|| {
            let ndc = glam::DVec4::new(
                (f64::from(x) + 0.5) / f64::from(width) * 2.0 - 1.0,
                1.0 - (f64::from(y) + 0.5) / f64::from(height) * 2.0,
                f64::from(d),
                1.0,
            );
            let p = clip.inverse() * ndc;
            p.truncate() / p.w
        })
    };
    let lin = |light: &Light, x: u32, y: u32, c: usize| f64::from(light[(y * width + x) as usize][c]);
    // Per channel: Σ dA², Σ dA dB, Σ T dA².
    let mut sums = [[0.0f64; 3]; 3];
    let mut pairs = 0;
    // The central third of the view (rays within ~11° of the nadir).
    for y in height / 3..2 * height / 3 {
        for x in width / 3..2 * width / 3 {
            let (Some(rel_m), Some(_)) = (ground(x, y), ground(x + 1, y)) else { continue };
            let point_km = camera_km + rel_m / 1000.0;
            let through = brute.sun_transmittance(point_km, -rel_m.normalize());
            pairs += 1;
            for (c, t) in through.iter().enumerate() {
                let da = lin(&clear, x + 1, y, c) - lin(&clear, x, y, c);
                let db = lin(&seen, x + 1, y, c) - lin(&seen, x, y, c);
                sums[c][0] += da * da;
                sums[c][1] += da * db;
                sums[c][2] += t * da * da;
            }
        }
    }
    assert!(pairs > 1000, "{pairs} pixel pairs");
    for (c, [squares, products, weighted]) in sums.into_iter().enumerate() {
        let (kept, truth) = (products / squares, weighted / squares);
        println!(
            "channel {c}: the frame keeps {kept:.4} of the contrast, the brute force's transmittance {truth:.4}"
        );
        assert!((kept / truth - 1.0).abs() < CONTRAST_OFF, "channel {c}: {kept} against {truth}");
    }
}
