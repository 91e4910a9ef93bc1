//! How it works: the `[faults]` table: faults injected into tile streaming, for tests and soak
//! runs that must show what a flaky disk or network share does to a flight. All zero (the
//! default) injects nothing and takes no other path. See `config/default.toml`.

use serde::Deserialize;

use super::{RangeCheck, SettingsError, first_out_of_range};

/// Faults injected into the loader's tile reads, see `config/default.toml` `[faults]`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSettings {
    /// Share of tiles whose read fails (an I/O error), 0 to 1.
    pub fail: f64,
    /// Share of tiles read with one byte flipped (the pack's checksum catches it), 0 to 1.
    pub corrupt: f64,
    /// Share of tiles read with one byte flipped under a checksum that matches it (the decoders
    /// meet the damage), 0 to 1.
    pub damage: f64,
    /// Each read waits up to this many milliseconds first (0 to 10000).
    pub delay_ms: u32,
    /// Which tiles fail, are corrupt or damaged and how long each waits: a hash of this and the
    /// tile.
    pub seed: u32,
}

impl FaultSettings {
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let checks: [RangeCheck; 4] = [
            ((0.0..=1.0).contains(&self.fail), "faults.fail", self.fail.to_string(), "0 to 1"),
            ((0.0..=1.0).contains(&self.corrupt), "faults.corrupt", self.corrupt.to_string(), "0 to 1"),
            ((0.0..=1.0).contains(&self.damage), "faults.damage", self.damage.to_string(), "0 to 1"),
            (
                self.delay_ms <= 10_000,
                "faults.delay_ms",
                self.delay_ms.to_string(),
                "0 to 10000 milliseconds",
            ),
        ];
        first_out_of_range(checks)
    }
}
