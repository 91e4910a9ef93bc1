//! How it works: fault injection into the loader's reads (`[faults]`, off by default), so that
//! tests and soak runs can show what failed, corrupt and slow reads do to a flight. Each tile's
//! fate is a hash of the faults' seed and the tile, so a run is repeatable: its read fails (an
//! injected I/O error); or its stored bytes arrive with one byte flipped and go through the pack's
//! own checks, either after their checksum was made (`Damage::Caught`: the checksum catches it) or
//! before (`Damage::Unseen`: the checksum matches, so the codec, the layer's range check and, for
//! imagery decoded on the CPU, the block decoder meet the damaged bytes); or it is read as usual.
//! Every read first waits its own share of `delay_ms`. With no fault set, `fate` is never asked.

use std::time::Duration;

use super::LayerKind;
use crate::config::FaultSettings;
use crate::dataset::TileId;

/// The faults a loader injects.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Faults(FaultSettings);

/// What happens to one read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// Read as usual.
    Read,
    /// Fails with an injected I/O error.
    Fail,
    /// Its stored bytes arrive with byte `at` (modulo their length) flipped after their checksum
    /// was made: the checksum catches it.
    Corrupt {
        /// Which stored byte is flipped.
        at: usize,
    },
    /// Its stored bytes arrive with byte `at` (modulo their length) flipped before their checksum
    /// was made: the decoders meet the damage.
    Damage {
        /// Which stored byte is flipped.
        at: usize,
    },
}

impl Faults {
    /// The faults `settings` ask for.
    pub fn new(settings: &FaultSettings) -> Self {
        Self(*settings)
    }

    /// Whether any fault is injected.
    pub fn any(&self) -> bool {
        let FaultSettings { fail, corrupt, damage, delay_ms, .. } = self.0;
        fail > 0.0 || corrupt > 0.0 || damage > 0.0 || delay_ms > 0
    }

    /// What happens to the read of `id` in `layer`, and how long it waits first.
    pub fn fate(&self, layer: LayerKind, id: TileId) -> (Fate, Duration) {
        let FaultSettings { fail, corrupt, damage, delay_ms, seed } = self.0;
        let key = u64::from(seed) << 32
            ^ (layer as u64) << 28
            ^ u64::from(id.level) << 24
            ^ u64::from(id.x) << 12
            ^ u64::from(id.y);
        let unit = |salt: u64| (mix(key ^ salt) >> 11) as f64 / (1u64 << 53) as f64;
        let wait = Duration::from_secs_f64(unit(3) * f64::from(delay_ms) / 1000.0);
        let fate = if unit(1) < fail {
            Fate::Fail
        } else if unit(2) < corrupt {
            Fate::Corrupt { at: mix(key ^ 4) as usize }
        } else if unit(5) < damage {
            Fate::Damage { at: mix(key ^ 4) as usize }
        } else {
            Fate::Read
        };
        (fate, wait)
    }
}

/// SplitMix64's finaliser: every bit of `v` moves every bit of the result.
fn mix(mut v: u64) -> u64 {
    v = (v ^ (v >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    v = (v ^ (v >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    v ^ (v >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_of_tiles_fail_and_are_corrupt_or_damaged_as_asked_and_the_same_every_time() {
        let settings = FaultSettings { fail: 0.2, corrupt: 0.1, damage: 0.3, delay_ms: 40, seed: 7 };
        let faults = Faults::new(&settings);
        let tiles: Vec<TileId> =
            (0..100).flat_map(|x| (0..100).map(move |y| TileId::new(x % 4, x, y))).collect();
        let fates: Vec<(Fate, Duration)> =
            tiles.iter().map(|&id| faults.fate(LayerKind::Imagery, id)).collect();
        let share = |f: fn(&Fate) -> bool| fates.iter().filter(|(fate, _)| f(fate)).count() as f64 / 1e4;
        // Shares of 10,000 hashed fates: five standard deviations of a fair draw's share (0.004 at
        // 0.2, 0.0027 at 0.08, 0.0041 at 0.216); a rule off by a quarter of its share fails.
        assert!((share(|f| *f == Fate::Fail) - 0.2).abs() < 0.02);
        // Corrupt among those that do not fail: 0.8 × 0.1; damaged among the rest: 0.8 × 0.9 × 0.3.
        assert!((share(|f| matches!(f, Fate::Corrupt { .. })) - 0.08).abs() < 0.015);
        assert!((share(|f| matches!(f, Fate::Damage { .. })) - 0.216).abs() < 0.02);
        assert!(fates.iter().all(|(_, wait)| *wait <= Duration::from_millis(40)));
        assert!(fates.iter().any(|(_, wait)| *wait > Duration::from_millis(30)));
        let again: Vec<_> = tiles.iter().map(|&id| faults.fate(LayerKind::Imagery, id)).collect();
        assert_eq!(fates, again);
        assert!(!Faults::default().any());
        assert!(Faults::new(&FaultSettings { damage: 0.1, ..Default::default() }).any());
    }
}
