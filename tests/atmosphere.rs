//! The atmosphere pass: its tables on the GPU against the twin, and the sky the tables give
//! against the brute-force model (`atmosphere::brute`), which shares no table with them.

use glam::DVec3;
use rayon::prelude::*;
use terramp::atmosphere::brute::Brute;
use terramp::config::{AtmosphereSettings, Settings};
use terramp::gpu::counter::Counting;
use terramp::gpu::gpu_types::AtmosphereUniforms;
use terramp::light::sun_dir;
use terramp::passes::atmosphere::frame::{SkyView, atmosphere_uniforms};
use terramp::passes::atmosphere::gpu::AtmospherePass;
use terramp::photo::colour::luminance;
use terramp::reference::atmosphere::{Model, Tables, tables};
use terramp::reference::display::shown;
use terramp::texcell::pyramid::encode_srgb;
use terramp_testkit::camera::over_fraction;
use terramp_testkit::{gpu, renderer, small_settings, synth_dataset};

/// The tables' sky against the brute force's, relative luminance: the mean and the largest over
/// the sample, the bounds (docs/atmosphere.md: 1.1 % and 5.9 % on this sample). The
/// single scattering agrees within 1 %; the higher orders, expanded to degree 2 in the view
/// direction, are the rest.
const SKY_MEAN_ERROR: f64 = 0.02;
const SKY_MAX_ERROR: f64 = 0.10;

/// Relative errors are taken against at least this luminance, per unit of the sun's irradiance
/// per steradian: 0.6 % of the zenith's at noon on the ground, so near-dark directions (twilight,
/// the night side of the limb) count by their absolute error.
const LUMINANCE_FLOOR: f64 = 1e-4;

/// The GPU's tables against the twin's: the transmittance's optical depth, relative...
const DEPTH_OFF: f32 = 5e-4;
/// ... the multiple-scattering texels, relative: each sums 5,120 f32 steps, and with the sun 5° to
/// 10° below the horizon high in the air the rays to it graze the Earth, where the adapter's
/// cosine moves which of them it hides (1.3 × 10⁻³ seen on lavapipe, 60 to 100 km up)...
const MULTIPLE_OFF: f32 = 2e-3;
/// ... the sky-view texels, relative, stored as f16: 10⁻³ for their f32 sums, and a step of f16
/// (2⁻¹⁰) where the two round either side of one...
const SKY_VIEW_OFF: f32 = 3e-3;
/// ... and the sky-view rows just below the horizon, whose rays graze the ground.
const GRAZING_OFF: f32 = 2e-2;
/// The aerial-perspective volume's last slice along a ray that leaves the air within its reach,
/// against the sky's light along that ray: two quadratures of one integral (the sky's 30
/// segments, the volume's 32 × 4)...
const AERIAL_SKY_OFF: f32 = 0.02;
/// ... and against the transmittance table's share to the top (40 segments).
const AERIAL_THROUGH_OFF: f32 = 0.01;
/// The drawn sky against the twin's, 8-bit levels.
const SKY_LEVELS: i32 = 2;

fn settings() -> AtmosphereSettings {
    Settings::default().atmosphere
}

/// The sun `elevation_deg` above the horizon, along +x.
fn sun(elevation_deg: f64) -> DVec3 {
    let e = elevation_deg.to_radians();
    DVec3::new(e.cos(), 0.0, e.sin())
}

fn view(altitude_m: f64, sun_elevation_deg: f64) -> SkyView {
    SkyView {
        view_world_from_clip: glam::DMat4::IDENTITY,
        up: DVec3::Z,
        sun_dir: sun(sun_elevation_deg),
        altitude_m,
    }
}

/// `count` directions spread evenly over the sphere (a Fibonacci lattice), or over the half
/// above the horizon with `upper`.
fn directions(count: usize, upper: bool) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let t = (i as f64 + 0.5) / count as f64;
            let z = if upper { 1.0 - t } else { 1.0 - 2.0 * t };
            let ring = (1.0 - z * z).max(0.0).sqrt();
            let a = golden * i as f64;
            DVec3::new(ring * a.cos(), ring * a.sin(), z)
        })
        .collect()
}

/// One altitude and sun: the tables' sky against the brute force's, per direction, as
/// (reference luminance, table luminance, the reference's standard error in luminance).
fn compare(altitude_m: f64, sun_elevation_deg: f64, dirs: &[DVec3], paths: u32) -> Vec<(f64, f64, f64)> {
    let s = settings();
    let u: AtmosphereUniforms = atmosphere_uniforms(&s, &view(altitude_m, sun_elevation_deg));
    let (transmittance, multiple, sky_view) = tables(&u);
    let lut = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
    let brute = Brute::new(s.air);
    // The view as the tables hold it (a camera on the ground sees from just above it).
    let origin = DVec3::new(0.0, 0.0, f64::from(u.radii[2]));
    let sun_dir = sun(sun_elevation_deg);
    dirs.par_iter()
        .enumerate()
        .filter(|(_, d)| d.dot(sun_dir) < (4.0 * s.air.sun_angular_radius_rad).cos())
        .map(|(i, &d)| {
            let reference = brute.sky(origin, d, sun_dir, paths, i as u64 * 7919 + 1);
            let table = lut.sky_radiance(&sky_view, d.as_vec3()).as_dvec3().to_array();
            (luminance(reference.radiance()), luminance(table), luminance(reference.multiple_std_error))
        })
        .collect()
}

/// Relative errors of the table's luminance, each against the larger of the reference and
/// `floor`: (mean, largest).
fn errors(pairs: &[(f64, f64, f64)], floor: f64) -> (f64, f64) {
    let each: Vec<f64> = pairs.iter().map(|&(r, t, _)| (t - r).abs() / r.max(floor)).collect();
    (each.iter().sum::<f64>() / each.len() as f64, each.iter().copied().fold(0.0, f64::max))
}

#[test]
fn the_gpu_makes_the_twins_tables() {
    let gpu = gpu();
    let s = settings();
    let pass = AtmospherePass::new(&gpu, &s);
    let sky = view(1500.0, 25.0);
    pass.prepare(&gpu.queue, &sky, &s);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    pass.encode_sky_view(&mut encoder, Counting::OFF);
    gpu.queue.submit([encoder.finish()]);
    let read = pass.read_back(&gpu).unwrap();
    let (transmittance, multiple, sky_view) = tables(&atmosphere_uniforms(&s, &sky));
    // The transmittance: f32 square roots and fused multiply-adds in the (r, μ) mapping move a
    // texel's optical depth by up to 5 × 10⁻⁴ of itself (2.4 × 10⁻⁴ seen on lavapipe).
    let depth_off = transmittance
        .texels
        .iter()
        .zip(&read[0])
        .flat_map(|(t, g)| (0..3).map(move |c| (t[c].ln() - g[c].ln()).abs() / (-t[c].ln()).max(1e-3)))
        .fold(0.0f32, f32::max);
    assert!(depth_off < DEPTH_OFF, "transmittance: optical depth off the twin by {depth_off:e} of itself");
    // Relative to each texel, or to a thousandth of its table's brightest where it is darker (the
    // multiple scattering of a sun far below the horizon is ~10⁻⁹).
    let brightest = |twin: &[[f32; 4]]| twin.iter().flat_map(|t| t[..3].to_vec()).fold(0.0f32, f32::max);
    let (multiple_floor, sky_floor) =
        (1e-3 * brightest(&multiple.texels), 1e-3 * brightest(&sky_view.texels));
    let off = |twin: &[[f32; 4]], gpu: &[[f32; 4]], texel: usize, floor: f32| {
        (0..3)
            .map(|c| (twin[texel][c] - gpu[texel][c]).abs() / twin[texel][c].abs().max(floor))
            .fold(0.0f32, f32::max)
    };
    // The others sum thousands of f32 steps each, relative to each texel...
    let multiple_off = (0..multiple.texels.len())
        .map(|i| off(&multiple.texels, &read[1], i, multiple_floor))
        .fold(0.0, f32::max);
    assert!(multiple_off < MULTIPLE_OFF, "multiple scattering off the twin by {multiple_off:e}");
    // ... except in the sky-view table's rows just below the horizon: their rays graze the
    // ground, and the adapter's cos (Vulkan allows 2⁻¹¹ of absolute error) moves where.
    let [width, height] = sky_view.size.map(|s| s as usize);
    let grazing = |row: usize| (height / 2..height / 2 + 3).contains(&row);
    let (mut away, mut near) = (0.0f32, 0.0f32);
    for texel in 0..sky_view.texels.len() {
        let e = off(&sky_view.texels, &read[2], texel, sky_floor);
        if grazing(texel / width) { near = near.max(e) } else { away = away.max(e) }
    }
    assert!(
        away < SKY_VIEW_OFF && near < GRAZING_OFF,
        "sky view off the twin by {away:e} (grazing rows {near:e})"
    );
    assert!(sky_view.texels.iter().all(|t| t[2] > 0.0), "a sky-view texel holds no light");
}

#[test]
fn the_frame_draws_the_twins_sky_where_nothing_else_is() {
    let dataset = synth_dataset(300, 7);
    let (width, height) = (96, 64);
    let mut settings = small_settings(width, height);
    settings.seeds.density_scale = 0.0;
    let mut r = renderer(&dataset, settings.clone());
    let camera = over_fraction(&r, [0.5, 0.5], 400.0, 30.0, 12.0);
    r.render(&camera).unwrap();
    let (colour, depth) = (r.read_colour().unwrap(), r.read_depth().unwrap());
    let clip = camera.clip_from_view(width, height).unwrap() * camera.view_from_world();
    let sky = SkyView {
        view_world_from_clip: clip.inverse(),
        up: DVec3::Z,
        sun_dir: sun_dir(&settings.render),
        altitude_m: camera.position_m.z,
    };
    let u = atmosphere_uniforms(&settings.atmosphere, &sky);
    let (transmittance, multiple, sky_view) = tables(&u);
    let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
    let daylight = twin.daylight_balance(&twin.irradiance_lut(settings.atmosphere.irradiance_lut));
    let display = terramp::passes::display::uniforms(&settings.display);
    let (mut sky_pixels, mut worst) = (0, 0i32);
    for (x, y, pixel) in colour.enumerate_pixels() {
        if depth[(y * width + x) as usize] != 0.0 {
            continue;
        }
        sky_pixels += 1;
        let ndc = glam::DVec4::new(
            (f64::from(x) + 0.5) / f64::from(width) * 2.0 - 1.0,
            1.0 - (f64::from(y) + 0.5) / f64::from(height) * 2.0,
            1.0,
            1.0,
        );
        let near = sky.view_world_from_clip * ndc;
        let dir = (near.truncate() / near.w).normalize().as_vec3();
        let expected =
            shown(&display, settings.display.tone_curve, daylight, twin.sky_colour(&sky_view, dir, daylight));
        for c in 0..3 {
            worst = worst.max((i32::from(pixel[c]) - i32::from(encode_srgb(expected[c]))).abs());
        }
    }
    // Half the frame looks above the horizon, the sky drawn and displayed (exposed, through the
    // tone curve) as the twins do it; its rounding to f16 and 8 bits and the adapter's
    // transcendentals: 2 levels.
    assert!(sky_pixels > (width * height / 4) as usize, "{sky_pixels} sky pixels");
    assert!(worst <= SKY_LEVELS, "the drawn sky is off the twin's by {worst} levels");
}

#[test]
fn the_tables_sky_is_the_brute_force_sky() {
    // A sample of the full comparison (`the_tables_sky_against_the_brute_force_in_full`): 32
    // directions × 4 suns × 3 views, 1,024 paths per channel each (the reference's own error is
    // about 1 % of a direction's luminance).
    let floor = LUMINANCE_FLOOR;
    let mut all = Vec::new();
    for (altitude_m, upper) in [(0.0, true), (10_000.0, false), (100_000.0, false)] {
        for sun_deg in [0.0, 10.0, 40.0, 90.0] {
            all.extend(compare(altitude_m, sun_deg, &directions(32, upper), 1024));
        }
    }
    let (mean, max) = errors(&all, floor);
    println!("{} directions: mean {:.4}, max {:.4}", all.len(), mean, max);
    assert!(mean <= SKY_MEAN_ERROR && max <= SKY_MAX_ERROR, "mean {mean}, max {max}");
}

#[test]
#[ignore = "minutes: the table in docs/atmosphere.md"]
fn the_tables_sky_against_the_brute_force_in_full() {
    let floor = LUMINANCE_FLOOR;
    let row = |view: String, sun: &str, pairs: &[(f64, f64, f64)]| {
        assert!(
            !pairs.is_empty() && pairs.iter().all(|p| p.0.is_finite() && p.1.is_finite()),
            "{view} {sun}"
        );
        let (mean, max) = errors(pairs, floor);
        let noise = pairs.iter().map(|&(r, _, e)| e / r.max(floor)).sum::<f64>() / pairs.len() as f64;
        println!(
            "| {view} | {sun} | {} | {:.2} % | {:.2} % | {:.2} % |",
            pairs.len(),
            mean * 100.0,
            max * 100.0,
            noise * 100.0
        );
    };
    println!("| view | sun | directions | mean | max | reference's own error (mean) |");
    println!("|---|---|---|---|---|---|");
    for (altitude_m, upper) in [(0.0, true), (10_000.0, false), (100_000.0, false)] {
        let view = format!("{} km", altitude_m / 1000.0);
        let mut day = Vec::new();
        for sun_deg in [-6.0, -3.0, 0.0, 5.0, 10.0, 20.0, 40.0, 60.0, 90.0] {
            let pairs = compare(altitude_m, sun_deg, &directions(120, upper), 1024);
            row(view.clone(), &format!("{sun_deg}°"), &pairs);
            if sun_deg >= 0.0 {
                day.extend(pairs);
            }
        }
        row(view, "**0° to 90°**", &day);
    }
}

#[test]
#[ignore = "a minute: the split in docs/atmosphere.md"]
fn the_parts_of_the_sky() {
    // Where the tables' error lies: their single scattering (the tables without the
    // multiple-scattering one) against the brute force's, and their higher orders (the rest)
    // against its Monte Carlo part, over the upper half of the sky.
    let s = settings();
    println!(
        "| view | sun | single: tables / truth | higher orders: tables / truth | higher orders' share |"
    );
    println!("|---|---|---|---|---|");
    for (altitude_m, sun_deg) in [(0.0, 90.0), (0.0, 40.0), (0.0, 10.0), (10_000.0, 40.0)] {
        let u = atmosphere_uniforms(&s, &view(altitude_m, sun_deg));
        let (transmittance, multiple, _) = tables(&u);
        let single = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: None };
        let full = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
        let (single_view, full_view) = (single.sky_view_lut(), full.sky_view_lut());
        let brute = Brute::new(s.air);
        let origin = DVec3::new(0.0, 0.0, f64::from(u.radii[2]));
        let parts: Vec<[f64; 3]> = directions(16, true)
            .par_iter()
            .map(|&d| {
                let truth = brute.sky(origin, d, sun(sun_deg), 4096, 3);
                let a = luminance(single.sky_radiance(&single_view, d.as_vec3()).as_dvec3().to_array());
                let b = luminance(full.sky_radiance(&full_view, d.as_vec3()).as_dvec3().to_array());
                let (rs, rm) = (luminance(truth.single), luminance(truth.multiple));
                [a / rs, (b - a) / rm, rm / (rs + rm)]
            })
            .collect();
        assert!(parts.iter().flatten().all(|v| v.is_finite() && *v > 0.0), "{parts:?}");
        let range = |k: usize| {
            let (lo, hi) =
                parts.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p[k]), hi.max(p[k])));
            format!("{lo:.3} to {hi:.3}")
        };
        println!("| {} km | {sun_deg}° | {} | {} | {} |", altitude_m / 1000.0, range(0), range(1), range(2));
    }
}

#[test]
#[ignore = "minutes: the table of sizes in docs/atmosphere.md"]
fn what_each_table_size_buys() {
    // The sky against the brute force as each table's size changes, the others at their defaults:
    // 48 directions × 6 suns from 0° to 90° × 3 views, 1,024 paths each, the truth computed once.
    let base = settings();
    let cases: Vec<(f64, bool, f64)> = [(0.0, true), (10_000.0, false), (100_000.0, false)]
        .into_iter()
        .flat_map(|(a, upper)| [0.0, 5.0, 10.0, 20.0, 40.0, 90.0].map(|sun| (a, upper, sun)))
        .collect();
    let brute = Brute::new(base.air);
    let truths: Vec<Vec<(DVec3, f64)>> = cases
        .iter()
        .map(|&(altitude_m, upper, sun_deg)| {
            let u = atmosphere_uniforms(&base, &view(altitude_m, sun_deg));
            let origin = DVec3::new(0.0, 0.0, f64::from(u.radii[2]));
            directions(48, upper)
                .into_par_iter()
                .enumerate()
                .filter(|(_, d)| d.dot(sun(sun_deg)) < (4.0 * base.air.sun_angular_radius_rad).cos())
                .map(|(i, d)| {
                    (d, luminance(brute.sky(origin, d, sun(sun_deg), 1024, i as u64 * 7919 + 1).radiance()))
                })
                .collect()
        })
        .collect();
    type Size = fn(&mut AtmosphereSettings) -> &mut [u32; 2];
    let tables_of: [(&str, Size, &[[u32; 2]]); 3] = [
        ("transmittance", |s| &mut s.transmittance_lut, &[[64, 16], [128, 32], [256, 64], [512, 128]]),
        ("multiple scattering", |s| &mut s.multiple_scattering_lut, &[[8, 8], [16, 16], [32, 32], [64, 64]]),
        ("sky view", |s| &mut s.sky_view_lut, &[[48, 27], [96, 54], [192, 108], [384, 216]]),
    ];
    println!("| table | size | mean | max |");
    println!("|---|---|---|---|");
    for (name, size_of, sizes) in tables_of {
        for &size in sizes {
            let mut s = base.clone();
            *size_of(&mut s) = size;
            let pairs: Vec<(f64, f64, f64)> = cases
                .iter()
                .zip(&truths)
                .flat_map(|(&(altitude_m, _, sun_deg), truth)| {
                    let u = atmosphere_uniforms(&s, &view(altitude_m, sun_deg));
                    let (transmittance, multiple, sky_view) = tables(&u);
                    let lut = Tables {
                        model: Model::new(&u),
                        transmittance: &transmittance,
                        multiple: Some(&multiple),
                    };
                    truth
                        .iter()
                        .map(|&(d, reference)| {
                            let table =
                                luminance(lut.sky_radiance(&sky_view, d.as_vec3()).as_dvec3().to_array());
                            (reference, table, 0.0)
                        })
                        .collect::<Vec<_>>()
                })
                .collect();
            let (mean, max) = errors(&pairs, LUMINANCE_FLOOR);
            assert!(mean.is_finite() && max.is_finite(), "{name} {size:?}");
            println!("| {name} | {} × {} | {:.2} % | {:.2} % |", size[0], size[1], mean * 100.0, max * 100.0);
        }
    }
}

#[test]
fn below_minus_18_degrees_it_is_night_a_dark_sky_and_no_nan() {
    // Astronomical night: the sun 20° below the horizon lights no air the view sees (the air's
    // top is 100 km up; the Earth's shadow covers it beyond ~350 km). Every table value finite,
    // the sky below one 8-bit level.
    let s = settings();
    let night = view(300.0, -20.0);
    let u = atmosphere_uniforms(&s, &night);
    let (transmittance, multiple, sky_view) = tables(&u);
    for lut in [&transmittance, &multiple, &sky_view] {
        assert!(lut.texels.iter().flatten().all(|v| v.is_finite()), "a table holds a NaN or an infinity");
    }
    let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
    let daylight = twin.daylight_balance(&twin.irradiance_lut(s.irradiance_lut));
    for d in directions(64, false) {
        let colour = twin.sky_colour(&sky_view, d.as_vec3(), daylight);
        assert!(colour.is_finite() && colour.max_element() < 0.5 / 255.0, "{d}: {colour}");
    }
    let dataset = synth_dataset(300, 7);
    let mut settings = small_settings(64, 48);
    settings.seeds.density_scale = 0.0;
    settings.render.sun_elevation_deg = -20.0;
    let mut r = renderer(&dataset, settings);
    let camera = over_fraction(&r, [0.5, 0.5], 300.0, 0.0, 20.0);
    r.render(&camera).unwrap();
    let (colour, depth) = (r.read_colour().unwrap(), r.read_depth().unwrap());
    let sky: Vec<_> = colour.pixels().zip(&depth).filter(|(_, d)| **d == 0.0).map(|(p, _)| p).collect();
    assert!(sky.len() > 64 * 48 / 4, "{} sky pixels", sky.len());
    assert!(sky.iter().all(|p| p[0] <= 1 && p[1] <= 1 && p[2] <= 1), "a night sky pixel is lit");
}

#[test]
fn the_gpu_makes_the_twins_aerial_perspective_and_its_far_slice_is_the_sky() {
    // A camera 1.5 km up looking 10° above level, 60° high: the upper tiles look into the sky,
    // the lower ones at the ground's horizon.
    let gpu = gpu();
    let s = settings();
    let camera = terramp::camera::Camera {
        position_m: DVec3::new(0.0, 0.0, 1500.0),
        yaw_deg: 90.0,
        pitch_deg: 10.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: 0.1,
    };
    let clip = camera.clip_from_view(320, 180).unwrap() * camera.view_from_world();
    let sky = SkyView {
        view_world_from_clip: clip.inverse(),
        up: DVec3::Z,
        sun_dir: sun(25.0),
        altitude_m: 1500.0,
    };
    let pass = AtmospherePass::new(&gpu, &s);
    pass.prepare(&gpu.queue, &sky, &s);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    pass.encode_aerial(&mut encoder, Counting::OFF);
    gpu.queue.submit([encoder.finish()]);
    let [inscatter, through] = pass.read_back_aerial(&gpu).unwrap();
    let u = atmosphere_uniforms(&s, &sky);
    let (transmittance, multiple, _) = tables(&u);
    let twin = Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
    let volume = twin.aerial_volume();
    for (name, twin, gpu) in
        [("in-scattering", &volume.inscatter, &inscatter), ("transmittance", &volume.transmittance, &through)]
    {
        let brightest = twin.iter().flat_map(|t| t[..3].to_vec()).fold(0.0f32, f32::max);
        let off = twin
            .iter()
            .zip(gpu)
            .flat_map(|(t, g)| (0..3).map(move |c| (t[c] - g[c]).abs() / t[c].abs().max(1e-3 * brightest)))
            .fold(0.0f32, f32::max);
        assert!(off < SKY_VIEW_OFF, "aerial {name}: GPU off the twin by {off:e}");
    }
    // Its last slice reaches past the air's top along the upper tiles' rays: there it holds the
    // sky's light along them and the transmittance table's share.
    let [w, h, slices] = volume.size;
    let x = w / 2;
    let y = 2;
    let ndc = glam::DVec4::new(
        (f64::from(x) + 0.5) / f64::from(w) * 2.0 - 1.0,
        1.0 - (f64::from(y) + 0.5) / f64::from(h) * 2.0,
        1.0,
        1.0,
    );
    let near = sky.view_world_from_clip * ndc;
    let dir = (near.truncate() / near.w).normalize().as_vec3();
    let (r, mu_sun) = (u.radii[2], u.radii[3]);
    let (mu, nu) = (dir.z, dir.dot(sun(25.0).as_vec3()));
    assert!(mu > 0.3, "the tile looks {mu} up");
    let last = (((slices - 1) * h + y) * w + x) as usize;
    let light = glam::Vec3::from_slice(&volume.inscatter[last][..3]);
    let expected = twin.in_scattered(r, mu, mu_sun, nu);
    let share = glam::Vec3::from_slice(&volume.transmittance[last][..3]);
    let to_top = twin.sun_transmittance(r, mu);
    for c in 0..3 {
        assert!(
            (light[c] / expected[c] - 1.0).abs() < AERIAL_SKY_OFF,
            "in-scattering {light} against the sky's {expected}"
        );
        assert!(
            (share[c] / to_top[c] - 1.0).abs() < AERIAL_THROUGH_OFF,
            "transmittance {share} against the table's {to_top}"
        );
    }
}
