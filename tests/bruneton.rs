//! The sky against an external anchor: Bruneton's reference implementation
//! (ebruneton/precomputed_atmospheric_scattering, its CPU model `atmosphere/reference`), which
//! precomputes the orders of scattering in 4D tables (Bruneton 2017) and shares nothing with
//! terramp. `scripts/bruneton_reference.sh` runs it on the atmosphere of his `model_test.cc` at
//! 680, 560 and 440 nm (`tests/bruneton_sky.txt`, 4 orders of scattering, and
//! `tests/bruneton_single.txt`, single scattering: the sky's radiance per unit of solar
//! irradiance at the zenith and 2° and 10° above the horizon, towards the sun, across and away,
//! with the sun from 2° to 90°, from 10 m and 10 km up); the same atmosphere is set here in
//! terramp's terms and its tables' sky (and, in the opt-in test, its brute force's) read along
//! the same rays.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DVec3;
use rayon::prelude::*;
use terramp::atmosphere::Atmosphere;
use terramp::atmosphere::brute::Brute;
use terramp::config::{AtmosphereSettings, Settings};
use terramp::passes::atmosphere::frame::{SkyView, atmosphere_uniforms};
use terramp::photo::colour::luminance;
use terramp::reference::atmosphere::{Model, Tables, tables};

/// The brute force's single scattering against Bruneton's, relative luminance: the mean over
/// every ray...
const SINGLE_MEAN: f64 = 0.01;
/// ... and the largest (within 10° of the sun, Mie's forward peak, which Bruneton's table holds
/// at 8 angles to the sun, and interpolates between).
const SINGLE_MAX: f64 = 0.03;
/// The tables' sky (every order) against Bruneton's (4 orders), relative luminance: the mean...
const BRUNETON_MEAN: f64 = 0.02;
/// ... and the largest.
const BRUNETON_MAX: f64 = 0.07;

/// One ray of `tests/bruneton_sky.txt`.
struct Ray {
    altitude_m: f64,
    sun_deg: f64,
    elevation_deg: f64,
    azimuth_deg: f64,
    /// Radiance per unit of solar irradiance at 680, 560 and 440 nm (terramp's red, green, blue).
    radiance: [f64; 3],
}

/// Bruneton's sky with 4 orders of scattering.
const SKY: &str = include_str!("bruneton_sky.txt");
/// His single scattering alone.
const SINGLE: &str = include_str!("bruneton_single.txt");

fn rays(text: &str) -> Vec<Ray> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|line| {
            let v: Vec<f64> = line.split_whitespace().map(|x| x.parse().unwrap()).collect();
            assert_eq!(v.len(), 7, "{line}");
            Ray {
                altitude_m: v[0],
                sun_deg: v[1],
                elevation_deg: v[2],
                azimuth_deg: v[3],
                radiance: [v[4], v[5], v[6]],
            }
        })
        .collect()
}

/// The atmosphere of Bruneton's `model_test.cc`, at 680, 560 and 440 nm.
fn bruneton_air() -> AtmosphereSettings {
    let lambda_um = [0.68, 0.56, 0.44];
    // 300 Dobson units in a tent 15 km wide at half height: molecules per m³ at its peak.
    let ozone_peak = 300.0 * 2.687e20 / 15_000.0;
    let ozone_cross_section_m2 = [1.209e-25, 4.266e-25, 1.582e-26];
    let mie_per_km = 5.328e-3 / 1.2;
    let air = Atmosphere {
        bottom_radius_km: 6360.0,
        top_radius_km: 6420.0,
        rayleigh_scattering_per_km: lambda_um.map(|l: f64| 1.24062e-3 * l.powi(-4)),
        rayleigh_scale_height_km: 8.0,
        mie_scattering_per_km: 0.9 * mie_per_km,
        mie_extinction_per_km: mie_per_km,
        mie_scale_height_km: 1.2,
        mie_g: 0.8,
        ozone_absorption_per_km: ozone_cross_section_m2.map(|s| ozone_peak * s * 1000.0),
        ozone_centre_km: 25.0,
        ozone_half_width_km: 15.0,
        ground_albedo: [0.1; 3],
        sun_angular_radius_rad: 0.2678f64.to_radians(),
    };
    AtmosphereSettings { air, ..Settings::default().atmosphere }
}

fn direction(elevation_deg: f64, azimuth_deg: f64) -> DVec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
}

/// What of terramp's sky a comparison reads.
#[derive(Clone, Copy)]
enum Ours {
    /// The tables' sky (the twin's, as the GPU draws it).
    Tables,
    /// The brute force's, every order, with this many paths.
    Brute(u32),
    /// The brute force's single scattering.
    BruteSingle,
}

/// Per ray of `reference` (those not within 4 sun radii of the sun, whose disk Bruneton's sky
/// leaves out): Bruneton's radiance and terramp's.
fn compare(reference: &str, ours: Ours) -> Vec<(Ray, [f64; 3])> {
    let s = bruneton_air();
    let rays = rays(reference);
    let mut views: Vec<(f64, f64)> = rays.iter().map(|r| (r.altitude_m, r.sun_deg)).collect();
    views.dedup();
    let ours: Vec<Vec<[f64; 3]>> = views
        .par_iter()
        .map(|&(altitude_m, sun_deg)| {
            let sun = direction(sun_deg, 0.0);
            let view = SkyView {
                view_world_from_clip: glam::DMat4::IDENTITY,
                up: DVec3::Z,
                sun_dir: sun,
                altitude_m,
            };
            let u = atmosphere_uniforms(&s, &view);
            let (transmittance, multiple, sky_view) = tables(&u);
            let lut =
                Tables { model: Model::new(&u), transmittance: &transmittance, multiple: Some(&multiple) };
            let brute = Brute::new(s.air);
            let origin = DVec3::new(0.0, 0.0, s.air.bottom_radius_km + altitude_m / 1000.0);
            rays.iter()
                .filter(|r| (r.altitude_m, r.sun_deg) == (altitude_m, sun_deg))
                .map(|r| {
                    let d = direction(r.elevation_deg, r.azimuth_deg);
                    match ours {
                        Ours::Tables => lut.sky_radiance(&sky_view, d.as_vec3()).as_dvec3().to_array(),
                        Ours::Brute(paths) => brute.sky(origin, d, sun, paths, 17).radiance(),
                        Ours::BruteSingle => brute.single_scattering(origin, d, sun),
                    }
                })
                .collect()
        })
        .collect();
    let sun_radius = s.air.sun_angular_radius_rad;
    rays.into_iter()
        .zip(ours.into_iter().flatten())
        .filter(|(r, _)| {
            direction(r.elevation_deg, r.azimuth_deg).dot(direction(r.sun_deg, 0.0))
                < (4.0 * sun_radius).cos()
        })
        .collect()
}

/// Prints the comparison as docs/atmosphere.md's table and returns the relative luminance
/// differences (terramp / Bruneton − 1).
fn table(what: &str, pairs: &[(Ray, [f64; 3])]) -> Vec<f64> {
    println!(
        "| view | sun | ray (elevation, azimuth from the sun) | Bruneton (680, 560, 440 nm) | {what} / Bruneton − 1 (luminance) |"
    );
    println!("|---|---|---|---|---|");
    pairs
        .iter()
        .map(|(r, ours)| {
            let off = luminance(*ours) / luminance(r.radiance) - 1.0;
            println!(
                "| {} m | {}° | {}°, {}° | {:.4}, {:.4}, {:.4} | {:+.1} % |",
                r.altitude_m,
                r.sun_deg,
                r.elevation_deg,
                r.azimuth_deg,
                r.radiance[0],
                r.radiance[1],
                r.radiance[2],
                off * 100.0
            );
            off
        })
        .collect()
}

/// The mean and largest of `offs`' magnitudes.
fn mean_and_max(offs: &[f64]) -> (f64, f64) {
    let mean = offs.iter().map(|o| o.abs()).sum::<f64>() / offs.len() as f64;
    (mean, offs.iter().fold(0.0f64, |m, o| m.max(o.abs())))
}

#[test]
fn the_tables_sky_is_bruneton_s_reference_sky() {
    let pairs = compare(SKY, Ours::Tables);
    assert!(pairs.len() >= 80, "{} rays", pairs.len());
    let (mean, max) = mean_and_max(&table("tables", &pairs));
    println!("{} rays: mean {:.2} %, largest {:.2} %", pairs.len(), mean * 100.0, max * 100.0);
    assert!(mean <= BRUNETON_MEAN && max <= BRUNETON_MAX, "mean {mean}, largest {max}");
}

#[test]
fn the_brute_force_s_single_scattering_is_bruneton_s() {
    let pairs = compare(SINGLE, Ours::BruteSingle);
    assert!(pairs.len() >= 80, "{} rays", pairs.len());
    let (mean, max) = mean_and_max(&table("brute force's single scattering", &pairs));
    println!("{} rays: mean {:.2} %, largest {:.2} %", pairs.len(), mean * 100.0, max * 100.0);
    assert!(mean <= SINGLE_MEAN && max <= SINGLE_MAX, "mean {mean}, largest {max}");
}

#[test]
#[ignore = "minutes: the brute force's column in docs/atmosphere.md"]
fn the_brute_force_sky_against_bruneton_s() {
    let pairs = compare(SKY, Ours::Brute(4096));
    let (mean, max) = mean_and_max(&table("brute force", &pairs));
    println!("{} rays: mean {:.2} %, largest {:.2} %", pairs.len(), mean * 100.0, max * 100.0);
}
