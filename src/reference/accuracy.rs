//! How it works: what the accuracy of pass 3 is measured as, against the exact oracle. Seeds are
//! compared by identity (global ring-0 cell address, rank), whatever their order:
//! - `SeedAgreement`: how many the oracle sees, how many the GPU kept, how many both hold; recall
//!   is common / visible (the visible seeds the GPU drew), precision common / kept (the kept seeds
//!   that are really visible). Agreements of several views add up, so a flight's recall is over all
//!   its seeds, not a mean of ratios.
//! - `HeightError`: how far each kept seed's ground height (`SeedRecord::ground_m`, before sinking)
//!   is from the f64 drawn ground under it (level 0, `Dataset::height_at`: the finest mesh's
//!   triangles, `dataset::surface`), in metres.

use std::collections::HashSet;

use glam::DVec3;
use serde::Serialize;

use crate::dataset::{Dataset, PackError};
use crate::earth::placing::ExactPlacing;
use crate::gpu::gpu_types::SeedRecord;
use crate::reference::oracle::OracleSeed;
use crate::reference::worst::max_or_nan;

/// A seed's identity: its ring-0 cell and its rank in the cell's pattern.
pub type SeedId = ([i64; 2], u32);

/// The identity of a record pass 3 wrote: its global ring-0 cell and rank, widened to the oracle's.
pub fn record_id(record: &SeedRecord) -> SeedId {
    ([i64::from(record.address[0]), i64::from(record.address[1])], record.rank)
}

/// How a kept seed set agrees with the oracle's visible set.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct SeedAgreement {
    /// Seeds the oracle sees.
    pub visible: u64,
    /// Seeds the GPU kept.
    pub kept: u64,
    /// Seeds in both.
    pub common: u64,
}

impl SeedAgreement {
    /// The agreement of pass 3's records (or its twin's) with the oracle's visible seeds of one view.
    pub fn of(kept: &[SeedRecord], visible: &[OracleSeed]) -> Self {
        Self::of_ids(kept.iter().map(record_id), visible.iter().map(|s| (s.address, s.rank)))
    }

    /// The agreement of two sets of identities (duplicates count once).
    pub fn of_ids(kept: impl IntoIterator<Item = SeedId>, visible: impl IntoIterator<Item = SeedId>) -> Self {
        let truth: HashSet<SeedId> = visible.into_iter().collect();
        let kept: HashSet<SeedId> = kept.into_iter().collect();
        Self {
            visible: truth.len() as u64,
            kept: kept.len() as u64,
            common: truth.intersection(&kept).count() as u64,
        }
    }

    /// Visible seeds kept, 0 to 1 (1 when nothing is visible: nothing was missed).
    pub fn recall(&self) -> f64 {
        if self.visible == 0 { 1.0 } else { self.common as f64 / self.visible as f64 }
    }

    /// Kept seeds that are visible, 0 to 1 (1 when nothing is kept: nothing is wrong).
    pub fn precision(&self) -> f64 {
        if self.kept == 0 { 1.0 } else { self.common as f64 / self.kept as f64 }
    }

    /// Visible seeds the GPU lost, and hidden ones it kept.
    pub fn missed(&self) -> u64 {
        self.visible - self.common
    }

    /// Kept seeds the oracle does not see: hidden or out-of-range ones the GPU kept anyway.
    pub fn extra(&self) -> u64 {
        self.kept - self.common
    }

    /// Adds another view's counts, so ratios are over all the seeds of a flight, not a mean of views'.
    pub fn add(&mut self, other: &Self) {
        self.visible += other.visible;
        self.kept += other.kept;
        self.common += other.common;
    }
}

/// The distance between kept seeds' ground heights and the f64 drawn ground (the finest mesh's
/// triangles), metres.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct HeightError {
    /// Largest error of any seed, metres; NaN when a seed's error is not finite (`non_finite`).
    pub max_m: f64,
    /// Sum of the errors, metres: kept rather than a mean so that views add up (`mean_m`).
    pub sum_m: f64,
    /// Seeds measured.
    pub seeds: u64,
    /// Seeds whose position or ground height is not finite (their error cannot be measured).
    pub non_finite: u64,
}

impl HeightError {
    /// `seeds` as pass 3 wrote them, placed by `placing` (the renderer's, from its camera): each
    /// seed's grid point is where the placing puts its anchor.
    pub fn of(dataset: &Dataset, placing: &ExactPlacing, seeds: &[SeedRecord]) -> Result<Self, PackError> {
        let mut out = Self::default();
        for s in seeds {
            let rel = DVec3::from(s.position_rel_m.map(f64::from));
            out.seeds += 1;
            if !(rel.is_finite() && s.ground_m.is_finite()) {
                out.non_finite += 1;
                out.max_m = f64::NAN;
                continue;
            }
            let DVec3 { x, y, .. } = placing.grid_m(rel);
            if !(x.is_finite() && y.is_finite()) {
                out.non_finite += 1;
                out.max_m = f64::NAN;
                continue;
            }
            let error_m = (f64::from(s.ground_m) - dataset.height_at(x, y, 0)?).abs();
            out.max_m = max_or_nan(out.max_m, error_m);
            out.sum_m += error_m;
        }
        Ok(out)
    }

    /// The mean error of the seeds measured, metres (0 without any).
    pub fn mean_m(&self) -> f64 {
        let measured = self.seeds - self.non_finite;
        if measured == 0 { 0.0 } else { self.sum_m / measured as f64 }
    }

    /// Adds another view's errors: the larger maximum, the summed sums and counts.
    pub fn add(&mut self, other: &Self) {
        self.max_m = max_or_nan(self.max_m, other.max_m);
        self.sum_m += other.sum_m;
        self.seeds += other.seeds;
        self.non_finite += other.non_finite;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(address: [i32; 2], rank: u32) -> SeedRecord {
        SeedRecord { address, rank, ..bytemuck::Zeroable::zeroed() }
    }

    #[test]
    fn recall_and_precision_count_identities() {
        let kept = [record([1, 2], 3), record([1, 2], 4), record([-5, 0], 0), record([1, 2], 4)];
        let truth = [([1, 2], 3), ([-5, 0], 0), ([7, 7], 1)];
        let a = SeedAgreement::of_ids(kept.iter().map(record_id), truth);
        assert_eq!((a.visible, a.kept, a.common), (3, 3, 2));
        assert!((a.recall() - 2.0 / 3.0).abs() < 1e-12 && (a.precision() - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!((a.missed(), a.extra()), (1, 1));
        let mut sum = a;
        sum.add(&SeedAgreement { visible: 1, kept: 3, common: 1 });
        assert_eq!((sum.recall(), sum.precision()), (0.75, 0.5));
        let none = SeedAgreement::default();
        assert_eq!((none.recall(), none.precision()), (1.0, 1.0));
    }
}
