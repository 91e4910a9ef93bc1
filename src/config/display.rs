//! How it works: the `[display]` table: how the frame's scene-referred light becomes the image a
//! screen shows (`passes::display`): a physical exposure as EV100 and a named tone curve,
//! range-checked like the rest of the settings. See `config/default.toml` for what each buys.

use serde::Deserialize;

use super::{SettingsError, first_out_of_range};

/// The exposures `display.ev100` may take: from a moonless dusk to snow under a high sun, with
/// room to spare either side.
pub const EV100_RANGE: std::ops::RangeInclusive<f64> = -10.0..=24.0;

/// The display, see `config/default.toml` `[display]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DisplaySettings {
    /// The exposure value at ISO 100 (EV100): 15 is "sunny 16", a sunlit landscape; each step
    /// down doubles the light the image shows.
    pub ev100: f64,
    /// The tone curve from scene light to the display.
    pub tone_curve: ToneCurve,
}

/// A tone curve: how scene light, any number of stops above white, is brought into the display's
/// range (`passes::display` holds each one's constants).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneCurve {
    /// Troy Sobotka's AgX (Blender's default since 4.0), in Wrensch's polynomial fit: mid-grey
    /// kept near the middle, bright colours drift towards white rather than towards pure hues.
    Agx,
    /// The Academy Color Encoding System's reference rendering and sRGB output transforms
    /// (RRT + ODT), in Stephen Hill's fit: a filmic S curve, more contrast, darker mid-tones.
    Aces,
    /// No exposure and no curve: the frame's light itself, balanced for daylight (white ground
    /// in daylight is 1) and clipped at white. What the photograph is measured against (`photo`).
    Linear,
}

impl ToneCurve {
    /// Every curve, in the order of their shader index.
    pub const ALL: [ToneCurve; 3] = [ToneCurve::Agx, ToneCurve::Aces, ToneCurve::Linear];

    /// The curve's name, as the settings spell it.
    pub fn name(self) -> &'static str {
        match self {
            ToneCurve::Agx => "agx",
            ToneCurve::Aces => "aces",
            ToneCurve::Linear => "linear",
        }
    }

    /// Its index: the display shader's `TONE_CURVE`.
    pub fn index(self) -> u32 {
        self as u32
    }
}

impl DisplaySettings {
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        first_out_of_range([(
            self.ev100.is_finite() && EV100_RANGE.contains(&self.ev100),
            "display.ev100",
            self.ev100.to_string(),
            "-10 to 24",
        )])
    }
}
