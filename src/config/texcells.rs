//! How it works: the `[texcells]` table: how far the texcell forest reaches, how many slices its
//! patches draw, the opacity correction's clamp, the ground colour it takes on, and where and how
//! finely silhouette texcells take over at grazing views; range-checked like the rest of the
//! settings. See `config/default.toml` for what each buys.

use serde::Deserialize;

use super::{DrawSeedsSettings, RangeCheck, SettingsError, first_out_of_range};

/// The most samples `texcells.silhouette_steps` may ask for.
pub const SILHOUETTE_MAX_STEPS: u32 = 256;

/// Drawing the far forest, see `config/default.toml` `[texcells]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TexcellSettings {
    /// How far texcells reach, metres; 0: none (no pass runs).
    pub reach_m: f64,
    /// Pixels of parallax between slices a patch's slice count aims for.
    pub slice_px: f64,
    /// The opacity correction's largest factor (the paper's k_M).
    pub opacity_max_factor: f64,
    /// How much of the imagery's colour under them texcells take on (0 to 1).
    pub ground_blend: f64,
    /// Where a pixel's ray descends less steeply than this, degrees below the horizon, silhouette
    /// texcells take over from the regular ones (dithered over the next half of it); 0: never.
    pub silhouette_deg: f64,
    /// The most samples a silhouette texcell's ray takes through the slab.
    pub silhouette_steps: u32,
}

impl TexcellSettings {
    /// Whether texcells are drawn at all.
    pub fn enabled(&self) -> bool {
        self.reach_m > 0.0
    }

    /// Whether silhouette texcells are drawn where the view grazes the canopy.
    pub fn silhouettes(&self) -> bool {
        self.enabled() && self.silhouette_deg > 0.0
    }

    pub(super) fn validate(&self, draw: &DrawSeedsSettings) -> Result<(), SettingsError> {
        let last = draw.reach_m[draw.reach_m.len() - 1];
        let checks: [RangeCheck; 6] = [
            (
                self.reach_m == 0.0 || (self.reach_m.is_finite() && self.reach_m > last),
                "texcells.reach_m",
                self.reach_m.to_string(),
                "0 (no texcells) or farther than the last of draw_seeds.reach_m",
            ),
            (
                self.slice_px.is_finite() && self.slice_px >= 0.1,
                "texcells.slice_px",
                self.slice_px.to_string(),
                "at least 0.1 pixels",
            ),
            (
                (1.0..=64.0).contains(&self.opacity_max_factor),
                "texcells.opacity_max_factor",
                self.opacity_max_factor.to_string(),
                "1 (no correction) to 64",
            ),
            (
                (0.0..=1.0).contains(&self.ground_blend),
                "texcells.ground_blend",
                self.ground_blend.to_string(),
                "0 to 1",
            ),
            (
                (0.0..=30.0).contains(&self.silhouette_deg),
                "texcells.silhouette_deg",
                self.silhouette_deg.to_string(),
                "0 (no silhouette texcells) to 30 degrees",
            ),
            (
                (1..=SILHOUETTE_MAX_STEPS).contains(&self.silhouette_steps),
                "texcells.silhouette_steps",
                self.silhouette_steps.to_string(),
                "1 to 256 samples",
            ),
        ];
        first_out_of_range(checks)
    }
}
