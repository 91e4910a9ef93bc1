//! How it works: the `[atmosphere]` table: the scattering model's parameters (`[atmosphere.air]`,
//! `atmosphere::Atmosphere`) and the sizes of the tables the GPU draws the sky from,
//! range-checked like the rest of the settings. See `config/default.toml` for what each buys.

use serde::Deserialize;

use super::{RangeCheck, SettingsError, first_out_of_range};
use crate::atmosphere::Atmosphere;

/// The largest side of an atmosphere table, texels.
const MAX_TABLE_SIDE: u32 = 4096;

/// The atmosphere, see `config/default.toml` `[atmosphere]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtmosphereSettings {
    /// The transmittance table's width (view zenith) and height (altitude), texels.
    pub transmittance_lut: [u32; 2],
    /// The multiple-scattering table's width (sun zenith) and height (altitude), texels, per
    /// term of its expansion in the view direction (six side by side).
    pub multiple_scattering_lut: [u32; 2],
    /// The sky-view table's width (azimuth) and height (zenith), texels.
    pub sky_view_lut: [u32; 2],
    /// The aerial-perspective volume's tiles across and down the screen, and its slices in depth.
    pub aerial_perspective_lut: [u32; 3],
    /// The sky-irradiance table's width (sun zenith) and height (altitude), texels.
    pub irradiance_lut: [u32; 2],
    /// Whether the ground, the seeds and the texcells are seen through the air (aerial
    /// perspective); off, they show their lit colours at any distance.
    pub aerial_perspective: bool,
    /// The air itself.
    pub air: Atmosphere,
}

impl AtmosphereSettings {
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let side = |size: [u32; 2]| size.iter().all(|s| (2..=MAX_TABLE_SIDE).contains(s));
        let text = |size: [u32; 2]| format!("{size:?}");
        let a = &self.air;
        let non_negative = |values: &[f64]| values.iter().all(|v| v.is_finite() && *v >= 0.0);
        let checks: [RangeCheck; 11] = [
            (
                side(self.transmittance_lut),
                "atmosphere.transmittance_lut",
                text(self.transmittance_lut),
                "2 to 4096 texels a side",
            ),
            (
                side(self.multiple_scattering_lut),
                "atmosphere.multiple_scattering_lut",
                text(self.multiple_scattering_lut),
                "2 to 4096 texels a side",
            ),
            (
                side(self.sky_view_lut),
                "atmosphere.sky_view_lut",
                text(self.sky_view_lut),
                "2 to 4096 texels a side",
            ),
            (
                self.aerial_perspective_lut.iter().all(|s| (2..=256).contains(s)),
                "atmosphere.aerial_perspective_lut",
                format!("{:?}", self.aerial_perspective_lut),
                "2 to 256 a side",
            ),
            (
                side(self.irradiance_lut),
                "atmosphere.irradiance_lut",
                text(self.irradiance_lut),
                "2 to 4096 texels a side",
            ),
            (
                a.bottom_radius_km > 0.0
                    && a.top_radius_km > a.bottom_radius_km
                    && a.top_radius_km.is_finite(),
                "atmosphere.air.top_radius_km",
                a.top_radius_km.to_string(),
                "above atmosphere.air.bottom_radius_km, which is above 0",
            ),
            (
                a.rayleigh_scale_height_km > 0.0
                    && a.mie_scale_height_km > 0.0
                    && a.ozone_half_width_km > 0.0,
                "atmosphere.air.mie_scale_height_km",
                format!(
                    "{} / {} / {}",
                    a.rayleigh_scale_height_km, a.mie_scale_height_km, a.ozone_half_width_km
                ),
                "scale heights and the ozone's half width above 0 km",
            ),
            (
                non_negative(&[a.rayleigh_scattering_per_km, a.ozone_absorption_per_km].concat())
                    && non_negative(&[a.mie_scattering_per_km, a.ozone_centre_km]),
                "atmosphere.air.rayleigh_scattering_per_km",
                format!("{:?}", a.rayleigh_scattering_per_km),
                "coefficients 0 or more per km",
            ),
            (
                a.mie_extinction_per_km.is_finite() && a.mie_extinction_per_km >= a.mie_scattering_per_km,
                "atmosphere.air.mie_extinction_per_km",
                a.mie_extinction_per_km.to_string(),
                "at least atmosphere.air.mie_scattering_per_km",
            ),
            ((0.0..1.0).contains(&a.mie_g), "atmosphere.air.mie_g", a.mie_g.to_string(), "0 to below 1"),
            (
                a.ground_albedo.iter().all(|v| (0.0..=1.0).contains(v))
                    && a.sun_angular_radius_rad > 0.0
                    && a.sun_angular_radius_rad < 0.1,
                "atmosphere.air.ground_albedo",
                format!("{:?}, sun {}", a.ground_albedo, a.sun_angular_radius_rad),
                "albedo 0 to 1 per channel, the sun's angular radius 0 to 0.1 rad",
            ),
        ];
        first_out_of_range(checks)
    }
}
