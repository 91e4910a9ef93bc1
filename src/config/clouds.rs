//! How it works: the `[clouds]` table: the cloud shadows' coverage, depth, size, drift and height
//! above the terrain, range-checked like the rest of the settings. The field they cast is
//! `light`; see `config/default.toml` for what each knob buys.

use serde::Deserialize;

use super::{RangeCheck, SettingsError, first_out_of_range};

/// The cloud shadows, see `config/default.toml` `[clouds]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudSettings {
    /// Share of the ground the clouds shade, 0 (none: no shadow anywhere) to 1 (overcast).
    pub coverage: f64,
    /// Share of the sunlight a cloud's core holds back, 0 to 1.
    pub shadow_depth: f64,
    /// Size of the clouds' largest features, metres.
    pub scale_m: f64,
    /// How fast the clouds drift, metres per second.
    pub speed_m_s: f64,
    /// Compass direction the clouds drift from, degrees clockwise from north.
    pub from_deg: f64,
    /// Height of the cloud layer above the dataset's highest point, metres: shadows fall along
    /// the sun from it.
    pub above_top_m: f64,
}

impl CloudSettings {
    /// Whether any cloud shades anything.
    pub fn casting(&self) -> bool {
        self.coverage > 0.0 && self.shadow_depth > 0.0
    }

    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let checks: [RangeCheck; 6] = [
            ((0.0..=1.0).contains(&self.coverage), "clouds.coverage", self.coverage.to_string(), "0 to 1"),
            (
                (0.0..=1.0).contains(&self.shadow_depth),
                "clouds.shadow_depth",
                self.shadow_depth.to_string(),
                "0 to 1",
            ),
            (
                self.scale_m.is_finite() && self.scale_m >= 1.0,
                "clouds.scale_m",
                self.scale_m.to_string(),
                "at least 1 metre",
            ),
            (
                (0.0..=200.0).contains(&self.speed_m_s),
                "clouds.speed_m_s",
                self.speed_m_s.to_string(),
                "0 to 200 metres per second",
            ),
            (
                self.from_deg.is_finite(),
                "clouds.from_deg",
                self.from_deg.to_string(),
                "a finite number of degrees",
            ),
            (
                self.above_top_m.is_finite() && self.above_top_m >= 0.0,
                "clouds.above_top_m",
                self.above_top_m.to_string(),
                "0 or more metres",
            ),
        ];
        first_out_of_range(checks)
    }
}
