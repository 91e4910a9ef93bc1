//! How it works: the `[seeds]` table (passes 3 and 4), range-checked like the rest of the
//! settings; see `config/default.toml` for what each knob buys and costs.

use serde::Deserialize;

use super::SettingsError;

/// Seed selection and drawing, see `config/default.toml` `[seeds]`. The dataset's class table is
/// checked against `seeds_per_pattern` by `seeds::SeedTables` (see `max_density_per_km2`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeedSettings {
    /// Seeds in each generic pattern (64 to 65536); a pattern covers one ring-0 TLM cell, so this
    /// bounds every class's density (see `max_density_per_km2`).
    pub seeds_per_pattern: u32,
    /// Seed records pass 3 can output per frame (1 to 16777216); seeds beyond it are dropped and
    /// counted as overflow.
    pub capacity: u32,
    /// Margin of the frustum test, NDC units (0 to 1): each side plane moves out by this fraction
    /// of the half-screen (the wind's sway grows the spheres themselves, `seeds::wind`).
    pub frustum_epsilon: f64,
    /// Constant part of the summit's occlusion tolerance, metres behind the terrain depth.
    pub occlusion_tolerance_m: f64,
    /// Part of the summit's occlusion tolerance that grows with distance, metres per km.
    pub occlusion_tolerance_per_km: f64,
    /// Most DEM samples of the march that settles a summit on a terrain silhouette (0, or a power
    /// of two up to 65536); 0 trusts the depth pixel.
    pub occlusion_refine_steps: u32,
    /// Every class's density is scaled by this (rank thinning: exactly that fraction).
    pub density_scale: f64,
    /// Seed height, metres, drawn out to the full `draw_seeds.reach_m`; smaller seeds' reaches
    /// shrink in proportion.
    pub reference_height_m: f64,
    /// How far a seed's anchor sinks into the ground, as a fraction of its height (0 to 0.5), so
    /// no gap shows under trunks on slopes.
    pub sink_fraction: f64,
    /// Radius around a seed in which its ground colour is sampled from the imagery, metres; 0
    /// samples the seed's own point.
    pub ground_colour_radius_m: f64,
    /// Where the imagery carries a vegetation index (`dataset::vegetation`): the index at and
    /// below which seeds and texcells grow none...
    pub vegetation_bare: f64,
    /// ... and at and above which they grow as densely as the class table says (linear between).
    pub vegetation_full: f64,
    /// A seed reads its class up to half a land-cover texel away, by a hash of its own, so class
    /// edges are dithered rather than a staircase of the land cover's cells.
    pub class_edge_dither: bool,
    /// "" = the table named by the dataset's land-cover scheme; else a built-in name or a path.
    pub class_table: String,
}

impl SeedSettings {
    /// The vegetation index's ramp for the shaders: where growth starts, and 1 / the span to full
    /// growth (`vegetation_bare`, `vegetation_full`; validated: the span is positive).
    pub fn vegetation_ramp(&self) -> [f32; 2] {
        let span = (self.vegetation_full - self.vegetation_bare).max(f64::EPSILON);
        [self.vegetation_bare as f32, (1.0 / span) as f32]
    }
}

/// How far behind the terrain's depth something must lie to count as hidden: `m` plus `per_km`
/// for every kilometre of distance, because the terrain mesh (and its depth) is coarser far
/// away. Seeds (`seeds.occlusion_tolerance_*`, their summits) and the Tile Load Map
/// (`tlm.occlusion_tolerance_*`, its cells' boxes) use this one model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OcclusionTolerance {
    /// The constant part, metres.
    pub m: f64,
    /// The part that grows with distance from the camera, metres per km.
    pub per_km: f64,
}

impl OcclusionTolerance {
    /// The per-metre slope, as the shaders take it.
    pub fn per_m(&self) -> f64 {
        self.per_km / 1000.0
    }
}

impl SeedSettings {
    /// The occlusion tolerance of a seed's summit.
    pub fn occlusion(&self) -> OcclusionTolerance {
        OcclusionTolerance { m: self.occlusion_tolerance_m, per_km: self.occlusion_tolerance_per_km }
    }

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
        let ramp_ok = (-1.0..1.0).contains(&s.vegetation_bare)
            && s.vegetation_bare < s.vegetation_full
            && s.vegetation_full <= 1.0;
        if !ramp_ok {
            let value = format!("{} to {}", s.vegetation_bare, s.vegetation_full);
            let rule = "−1 ≤ seeds.vegetation_bare < seeds.vegetation_full ≤ 1 (vegetation index)";
            return Err(SettingsError::OutOfRange { key: "seeds.vegetation_bare", value, rule });
        }
        let ranges: [(&'static str, f64, f64, f64, &'static str); 9] = [
            ("seeds.seeds_per_pattern", s.seeds_per_pattern.into(), 64.0, 65536.0, "64 to 65536 seeds"),
            ("seeds.capacity", s.capacity.into(), 1.0, 16_777_216.0, "1 to 16777216 seeds"),
            ("seeds.frustum_epsilon", s.frustum_epsilon, 0.0, 1.0, "0 to 1 (NDC units)"),
            ("seeds.occlusion_tolerance_m", s.occlusion_tolerance_m, 0.0, any, "0 or more metres"),
            ("seeds.occlusion_tolerance_per_km", s.occlusion_tolerance_per_km, 0.0, any, "0 or more m/km"),
            ("seeds.reference_height_m", s.reference_height_m, tiny, any, "a positive number of metres"),
            ("seeds.sink_fraction", s.sink_fraction, 0.0, 0.5, "0 to 0.5 of the seed's height"),
            ("seeds.ground_colour_radius_m", s.ground_colour_radius_m, 0.0, any, "0 or more metres"),
            ("seeds.density_scale", s.density_scale, 0.0, 1.0, "0 to 1 of the class table's densities"),
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
