//! How it works: the `[wind]` table: the wind's speed and direction and how a flight's frame
//! numbers become wind time, range-checked like the rest of the settings. What the wind does to
//! each plant is `seeds::wind`; see `config/default.toml` for what each knob buys.

use serde::Deserialize;

use super::{RangeCheck, SettingsError, first_out_of_range};

/// The fastest wind `wind.speed_m_s` accepts, metres per second (a storm).
pub const MAX_WIND_M_S: f64 = 40.0;

/// The wind, see `config/default.toml` `[wind]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindSettings {
    /// Wind speed, metres per second; 0: still air.
    pub speed_m_s: f64,
    /// Compass direction the wind blows from, degrees clockwise from north.
    pub from_deg: f64,
    /// Frames per second of the scene's time (wind, clouds) along a flight (frame n is at n / this
    /// seconds).
    pub frame_rate_hz: f64,
}

impl WindSettings {
    /// Wind time of a flight's frame `n`, seconds.
    pub fn time_of_frame_s(&self, n: usize) -> f64 {
        n as f64 / self.frame_rate_hz
    }

    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let checks: [RangeCheck; 3] = [
            (
                (0.0..=MAX_WIND_M_S).contains(&self.speed_m_s),
                "wind.speed_m_s",
                self.speed_m_s.to_string(),
                "0 to 40 metres per second",
            ),
            (
                self.from_deg.is_finite(),
                "wind.from_deg",
                self.from_deg.to_string(),
                "a finite number of degrees",
            ),
            (
                self.frame_rate_hz.is_finite() && self.frame_rate_hz > 0.0,
                "wind.frame_rate_hz",
                self.frame_rate_hz.to_string(),
                "a positive number of frames per second",
            ),
        ];
        first_out_of_range(checks)
    }
}
