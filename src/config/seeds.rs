//! How it works: the `[seeds]` table (passes 3 and 4), range-checked like the rest of the
//! settings; see `config/default.toml` for what each knob buys and costs.

use serde::Deserialize;

use super::SettingsError;

/// Seed selection and drawing, see `config/default.toml` `[seeds]`. The dataset's class table is
/// checked against `seeds_per_pattern` by `seeds::SeedTables` (see `max_density_per_km2`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeedSettings {
    pub seeds_per_pattern: u32,
    pub capacity: u32,
    pub frustum_epsilon: f64,
    pub occlusion_tolerance_m: f64,
    pub occlusion_tolerance_per_km: f64,
    pub occlusion_refine_steps: u32,
    /// Every class's density is scaled by this (rank thinning: exactly that fraction).
    pub density_scale: f64,
    pub reference_height_m: f64,
    pub sink_fraction: f64,
    pub ground_colour_radius_m: f64,
    /// A seed of `reference_height_m` nearer than this is drawn with its real mesh (smaller seeds
    /// in proportion, like the radial LODs); farther, with its billboard clouds.
    pub mesh_m: f64,
    /// The outer part of each LOD's reach over which a seed cross-fades into the next LOD (the
    /// last LOD: fades out), as a fraction of the reach; 0 switches at once (pops).
    pub fade_fraction: f64,
    /// "" = the table named by the dataset's land-cover scheme; else a built-in name or a path.
    pub class_table: String,
    /// Folder of baked impostors (`terramp-data bake`), one sub-folder per model; "" = seeds are
    /// selected but not drawn. Species whose model is not there are not drawn.
    pub impostors: String,
}

impl SeedSettings {
    /// Most seeds per km² a class can ask for: one full pattern per ring-0 cell of `cell_m` metres.
    pub fn max_density_per_km2(&self, cell_m: f64) -> f64 {
        f64::from(self.seeds_per_pattern) / (cell_m * cell_m * 1e-6)
    }

    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let s = self;
        let (any, tiny) = (f64::MAX, f64::MIN_POSITIVE);
        let steps = s.occlusion_refine_steps;
        if !(steps == 0 || steps.is_power_of_two() && steps <= 65536) {
            let (key, rule) = ("seeds.occlusion_refine_steps", "0 or a power of two up to 65536");
            return Err(SettingsError::OutOfRange { key, value: steps.to_string(), rule });
        }
        let ranges: [(&'static str, f64, f64, f64, &'static str); 11] = [
            ("seeds.seeds_per_pattern", s.seeds_per_pattern.into(), 64.0, 65536.0, "64 to 65536 seeds"),
            ("seeds.capacity", s.capacity.into(), 1.0, 16_777_216.0, "1 to 16777216 seeds"),
            ("seeds.frustum_epsilon", s.frustum_epsilon, 0.0, 1.0, "0 to 1 (NDC units)"),
            ("seeds.occlusion_tolerance_m", s.occlusion_tolerance_m, 0.0, any, "0 or more metres"),
            ("seeds.occlusion_tolerance_per_km", s.occlusion_tolerance_per_km, 0.0, any, "0 or more m/km"),
            ("seeds.reference_height_m", s.reference_height_m, tiny, any, "a positive number of metres"),
            ("seeds.sink_fraction", s.sink_fraction, 0.0, 0.5, "0 to 0.5 of the seed's height"),
            ("seeds.ground_colour_radius_m", s.ground_colour_radius_m, 0.0, any, "0 or more metres"),
            ("seeds.density_scale", s.density_scale, 0.0, 1.0, "0 to 1 of the class table's densities"),
            ("seeds.mesh_m", s.mesh_m, 0.0, any, "0 (never) or more metres"),
            ("seeds.fade_fraction", s.fade_fraction, 0.0, 0.5, "0 to 0.5 of each LOD's reach"),
        ];
        // NaN and infinities fall outside every range.
        match ranges.into_iter().find(|(_, value, lo, hi, _)| !(*lo..=*hi).contains(value)) {
            Some((key, value, .., rule)) => {
                Err(SettingsError::OutOfRange { key, value: value.to_string(), rule })
            }
            None => Ok(()),
        }
    }
}
