//! The atmosphere pass's frame half: the uniforms from the settings and the view.

use glam::{DMat4, DVec3};

use crate::atmosphere::{Atmosphere, legendre_moments, mie_phase, rayleigh_phase};
use crate::config::AtmosphereSettings;
use crate::gpu::gpu_types::AtmosphereUniforms;

/// The lowest a view sits above the model's ground, km: a camera below sea level (or on it) sees
/// the sky from just above the ground, where a ray level with it still leaves the air.
const LOWEST_VIEW_KM: f64 = 1e-3;

/// Where the sky is seen from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyView {
    /// Camera-relative world (the frame's own) from clip space.
    pub view_world_from_clip: DMat4,
    /// The view's zenith in that space (unit).
    pub up: DVec3,
    /// Towards the sun in that space (unit).
    pub sun_dir: DVec3,
    /// The camera's height above the model's ground (the datum), metres.
    pub altitude_m: f64,
}

/// How far the aerial-perspective volume reaches from a view at `view_radius_km`: to the ground's
/// horizon and on to where that line leaves the air, the farthest ground the view can see.
pub fn aerial_far_km(air: &Atmosphere, view_radius_km: f64) -> f64 {
    let (bottom, top) = (air.bottom_radius_km, air.top_radius_km);
    (view_radius_km.powi(2) - bottom * bottom).max(0.0).sqrt() + (top * top - bottom * bottom).sqrt()
}

/// The phase functions' Legendre moments as the uniforms carry them, [Rayleigh k₂, Mie k₁, Mie
/// k₂, 0] (Rayleigh's k₁ is zero): what the multiple-scattering table weighs its degrees by.
/// Two quadratures of 4,000 bands, so made once per air, not per frame.
pub fn phase_moments(air: &Atmosphere) -> [f32; 4] {
    let rayleigh = legendre_moments(rayleigh_phase);
    let mie = legendre_moments(|nu| mie_phase(nu, air.mie_g));
    [rayleigh[1] as f32, mie[0] as f32, mie[1] as f32, 0.0]
}

/// The pass's uniforms for `view` over the air of `settings`, its phase moments computed here
/// (`frame_uniforms` takes them made once).
pub fn atmosphere_uniforms(settings: &AtmosphereSettings, view: &SkyView) -> AtmosphereUniforms {
    frame_uniforms(settings, view, phase_moments(&settings.air))
}

/// The pass's uniforms for `view` over the air of `settings`, whose phase moments
/// (`phase_moments`) are given. The sky-view table is made for the view's radius within the air
/// (at its top for a view above it, which marches its sky per pixel); the aerial-perspective
/// volume is marched from the view itself, wherever it is.
pub fn frame_uniforms(
    settings: &AtmosphereSettings,
    view: &SkyView,
    phase_moments: [f32; 4],
) -> AtmosphereUniforms {
    let a = &settings.air;
    let thickness_km = a.top_radius_km - a.bottom_radius_km;
    let altitude_km = (view.altitude_m / 1000.0).max(LOWEST_VIEW_KM);
    let view_radius_km = a.bottom_radius_km + altitude_km.min(thickness_km);
    let f = |v: f64| v as f32;
    let rgb = |v: [f64; 3], w: f64| [f(v[0]), f(v[1]), f(v[2]), f(w)];
    AtmosphereUniforms {
        rayleigh: rgb(a.rayleigh_scattering_per_km, a.rayleigh_scale_height_km),
        mie: [f(a.mie_scattering_per_km), f(a.mie_extinction_per_km), f(a.mie_scale_height_km), f(a.mie_g)],
        phase_moments,
        ozone: rgb(a.ozone_absorption_per_km, a.ozone_centre_km),
        albedo: rgb(a.ground_albedo, a.ozone_half_width_km),
        radii: [
            f(a.bottom_radius_km),
            f(a.top_radius_km),
            f(view_radius_km),
            f(view.sun_dir.dot(view.up).clamp(-1.0, 1.0)),
        ],
        view_world_from_clip: view.view_world_from_clip.as_mat4().to_cols_array_2d(),
        clip_from_view_world: view.view_world_from_clip.inverse().as_mat4().to_cols_array_2d(),
        up: view.up.as_vec3().extend(f(a.bottom_radius_km + altitude_km)).to_array(),
        sun_dir: view.sun_dir.as_vec3().extend(f(a.sun_angular_radius_rad)).to_array(),
        transmittance_size: settings.transmittance_lut,
        multiple_size: settings.multiple_scattering_lut,
        sky_view_size: settings.sky_view_lut,
        aerial_size: [settings.aerial_perspective_lut[0], settings.aerial_perspective_lut[1]],
        aerial_far_km: f(aerial_far_km(a, a.bottom_radius_km + altitude_km)),
        aerial_slices: settings.aerial_perspective_lut[2],
        aerial_on: u32::from(settings.aerial_perspective),
        _pad: 0,
    }
}
