//! How it works: the any-part visibility oracle. The ground truth's id buffer names, per
//! supersample, the seed drawn there (its index + 1; 0 for terrain or sky); a seed is visible when
//! at least one of its samples survives the depth test, whatever part of it that is (a leaf over a
//! ridge, a crown poking into the view from outside it). Against that set, a selection (the GPU's
//! seeds, named by their identity: ring-0 cell address and rank) is judged by recall (visible
//! seeds selected), precision (selected seeds visible) and pixel-weighted recall (the share of the
//! truth's seed samples whose seed is selected): missing a tree that covers a hundred pixels costs
//! a hundred times one that covers one. `missed` says why the samples a selection misses are
//! missed: the fate the exact oracle gives each missed seed under the selection's own settings
//! (beyond its reach, thinned by its density, outside its frustum, its summit hidden), or, when
//! the exact rule keeps it, the selection's own approximations.

use std::collections::HashSet;

use serde::Serialize;

use crate::reference::oracle::{Culls, Fate, OracleError, OracleInputs, OracleSeed, fates_of};

/// How a selection of seeds compares with the truth's visible ones.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Visibility {
    /// Seeds with at least one sample in the truth.
    pub visible: u64,
    /// Seeds the selection holds.
    pub selected: u64,
    /// Selected seeds that are visible.
    pub selected_visible: u64,
    /// Supersamples showing a seed in the truth.
    pub seed_samples: u64,
    /// Of those, the samples whose seed is selected.
    pub seed_samples_selected: u64,
}

impl Visibility {
    /// Visible seeds selected (1 when none is visible).
    pub fn recall(&self) -> f64 {
        ratio(self.selected_visible, self.visible)
    }

    /// Selected seeds visible (1 when none is selected).
    pub fn precision(&self) -> f64 {
        ratio(self.selected_visible, self.selected)
    }

    /// The truth's seed samples whose seed is selected (1 when no sample shows a seed).
    pub fn pixel_weighted_recall(&self) -> f64 {
        ratio(self.seed_samples_selected, self.seed_samples)
    }

    /// Sums two views' counts (recall and the rest are then over both).
    pub fn add(&mut self, other: &Self) {
        self.visible += other.visible;
        self.selected += other.selected;
        self.selected_visible += other.selected_visible;
        self.seed_samples += other.seed_samples;
        self.seed_samples_selected += other.seed_samples_selected;
    }
}

/// The truth's seed samples a selection misses, by why: the fate of their seed under the
/// selection's own rule done exactly (the summit oracle with the selection's settings).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Missed {
    /// Beyond the selection's reach for the seed's size (`draw_seeds.reach_m`, scaled).
    pub reach: u64,
    /// Not grown by the selection: thinned by its density (`seeds.density_scale`), or its class
    /// or rules.
    pub density: u64,
    /// Its bounding sphere outside the view (a crown poking in from beyond the frustum's test).
    pub frustum: u64,
    /// Its summit hidden by the terrain while another part of it shows.
    pub summit_hidden: u64,
    /// Kept by the exact rule, yet not selected: what the selection's approximations lose (the
    /// Tile Load Map's cells, depth tolerances, overflow).
    pub selection: u64,
}

impl Missed {
    /// Sums two views' samples.
    pub fn add(&mut self, other: &Self) {
        self.reach += other.reach;
        self.density += other.density;
        self.frustum += other.frustum;
        self.summit_hidden += other.summit_hidden;
        self.selection += other.selection;
    }
}

/// Why the truth's visible `seeds` (with `samples` each) that `selected` leaves out are missed,
/// judged by the oracle in the selection's view (`inputs`: its settings, seeded world and camera).
pub fn missed(
    inputs: &OracleInputs,
    seeds: &[OracleSeed],
    samples: &[u64],
    selected: impl IntoIterator<Item = ([i64; 2], u32)>,
) -> Result<Missed, OracleError> {
    let selected: HashSet<([i64; 2], u32)> = selected.into_iter().collect();
    let (left_out, weights): (Vec<OracleSeed>, Vec<u64>) = seeds
        .iter()
        .zip(samples)
        .filter(|&(s, &n)| n > 0 && !selected.contains(&(s.address, s.rank)))
        .map(|(s, &n)| (*s, n))
        .unzip();
    let mut out = Missed::default();
    for (fate, n) in fates_of(inputs, Culls::SELECTION, &left_out)?.into_iter().zip(weights) {
        let bin = match fate {
            Fate::Distance => &mut out.reach,
            Fate::Class | Fate::Rule => &mut out.density,
            Fate::Frustum => &mut out.frustum,
            Fate::Occlusion => &mut out.summit_hidden,
            Fate::Visible(_) => &mut out.selection,
        };
        *bin += n;
    }
    Ok(out)
}

fn ratio(part: u64, whole: u64) -> f64 {
    if whole == 0 { 1.0 } else { part as f64 / whole as f64 }
}

/// Samples per seed of `seeds` in `seed_ids` (id = index + 1; 0 and ids beyond are no seed).
pub fn samples_per_seed(seed_ids: &[u32], seeds: usize) -> Vec<u64> {
    let mut samples = vec![0u64; seeds];
    for &id in seed_ids {
        if let Some(n) = (id as usize).checked_sub(1).and_then(|i| samples.get_mut(i)) {
            *n += 1;
        }
    }
    samples
}

/// Judges `selected` (seed identities: cell address, rank; duplicates count once) against the
/// truth's `seeds` and the samples each shows (`samples_per_seed`).
pub fn judge(
    seeds: &[OracleSeed],
    samples: &[u64],
    selected: impl IntoIterator<Item = ([i64; 2], u32)>,
) -> Visibility {
    let selected: HashSet<([i64; 2], u32)> = selected.into_iter().collect();
    let mut v = Visibility { selected: selected.len() as u64, ..Default::default() };
    for (seed, &n) in seeds.iter().zip(samples) {
        if n == 0 {
            continue;
        }
        v.visible += 1;
        v.seed_samples += n;
        if selected.contains(&(seed.address, seed.rank)) {
            v.selected_visible += 1;
            v.seed_samples_selected += n;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seed(x: i64, rank: u32) -> OracleSeed {
        OracleSeed {
            address: [x, 0],
            rank,
            species: 0,
            position_grid_m: [0.0; 2],
            ground_m: 0.0,
            height_m: 1.0,
            lod: 0,
        }
    }

    #[test]
    fn a_seed_is_visible_by_any_sample_and_weighs_by_its_samples() {
        let seeds = [seed(0, 0), seed(0, 1), seed(1, 0)];
        // Seed 0 shows 3 samples, seed 1 one (a single leaf), seed 2 none (hidden).
        let ids = [1, 1, 0, 2, 1, 0, 7];
        let samples = samples_per_seed(&ids, seeds.len());
        assert_eq!(samples, [3, 1, 0]);
        let v = judge(&seeds, &samples, [([0, 0], 1), ([1, 0], 0), ([9, 9], 0)]);
        assert_eq!((v.visible, v.selected, v.selected_visible), (2, 3, 1));
        assert_eq!((v.seed_samples, v.seed_samples_selected), (4, 1));
        assert_eq!(v.recall(), 0.5);
        assert_eq!(v.precision(), 1.0 / 3.0);
        assert_eq!(v.pixel_weighted_recall(), 0.25);
        let none = judge(&seeds, &[0, 0, 0], []);
        assert_eq!((none.recall(), none.precision(), none.pixel_weighted_recall()), (1.0, 1.0, 1.0));
    }
}
