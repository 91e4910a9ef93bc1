//! How it works: compares two seed sets by identity (cell address, rank), whatever their order:
//! which seeds only one side has, which common ones disagree on what they are (species, LOD,
//! levels, jitter), and how far their lengths and ground colours differ. A length that is not
//! finite, on either side, is never lost in a maximum: its seed and field are listed, and the
//! largest length error becomes NaN, so no exactness check can pass over it.

use std::collections::{HashMap, HashSet};

use crate::gpu::gpu_types::SeedRecord;
use crate::reference::worst::max_or_nan;

/// How two seed sets differ, keyed by identity (cell address, rank).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SeedComparison {
    /// Seeds both sets hold.
    pub common: usize,
    /// In the twin's set, not in the GPU's; and the reverse.
    pub only_twin: Vec<([i32; 2], u32)>,
    /// In the GPU's set, not in the twin's.
    pub only_gpu: Vec<([i32; 2], u32)>,
    /// Common seeds whose species, LOD, levels or jitter differ.
    pub mismatched: Vec<([i32; 2], u32)>,
    /// Largest difference of position, height, radius or ground height, metres; NaN when any
    /// of them is not finite on either side (`non_finite`).
    pub max_length_error_m: f32,
    /// Seeds of either set with a length that is not finite, and the field's name.
    pub non_finite: Vec<(([i32; 2], u32), &'static str)>,
    /// Largest difference of a ground-colour channel, in 1/255.
    pub max_colour_error: u32,
}

impl SeedComparison {
    /// Compares pass 3's records with its twin's, in any order; each `only_*` list keeps its own set's order.
    pub fn of(gpu: &[SeedRecord], twin: &[SeedRecord]) -> Self {
        let key = |r: &SeedRecord| (r.address, r.rank);
        let gpu_by_key: HashMap<_, _> = gpu.iter().map(|r| (key(r), r)).collect();
        let twin_keys: HashSet<_> = twin.iter().map(key).collect();
        let mut out = Self::default();
        for r in gpu.iter().chain(twin) {
            out.non_finite
                .extend(lengths(r).into_iter().filter(|(_, v)| !v.is_finite()).map(|(f, _)| (key(r), f)));
        }
        for t in twin {
            let Some(g) = gpu_by_key.get(&key(t)) else {
                out.only_twin.push(key(t));
                continue;
            };
            out.common += 1;
            if (g.species_lod, g.jitter) != (t.species_lod, t.jitter) {
                out.mismatched.push(key(t));
            }
            for ((_, a), (_, b)) in lengths(g).into_iter().zip(lengths(t)) {
                let error = f64::from((a - b).abs());
                out.max_length_error_m = max_or_nan(f64::from(out.max_length_error_m), error) as f32;
            }
            for c in 0..4 {
                let channel = |w: u32| (w >> (8 * c)) & 0xff;
                out.max_colour_error =
                    out.max_colour_error.max(channel(g.ground_colour).abs_diff(channel(t.ground_colour)));
            }
        }
        out.only_gpu = gpu.iter().map(key).filter(|k| !twin_keys.contains(k)).collect();
        if !out.non_finite.is_empty() {
            out.max_length_error_m = f32::NAN;
        }
        out
    }
}

/// A record's lengths, named.
fn lengths(r: &SeedRecord) -> [(&'static str, f32); 6] {
    [
        ("position_rel_m.x", r.position_rel_m[0]),
        ("position_rel_m.y", r.position_rel_m[1]),
        ("position_rel_m.z", r.position_rel_m[2]),
        ("height_m", r.height_m),
        ("radius_m", r.radius_m),
        ("ground_m", r.ground_m),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(rank: u32, height_m: f32) -> SeedRecord {
        SeedRecord { address: [3, -4], rank, height_m, radius_m: 1.0, ..Default::default() }
    }

    #[test]
    fn a_nan_in_one_gpu_field_fails_the_comparison() {
        let twin = [record(0, 8.0), record(1, 9.0)];
        let same = SeedComparison::of(&twin, &twin);
        assert_eq!((same.common, same.max_length_error_m, same.non_finite.len()), (2, 0.0, 0));
        // `f32::max` would have kept 0.0 here: the NaN must surface instead.
        let gpu = [record(0, 8.0), record(1, f32::NAN)];
        let diff = SeedComparison::of(&gpu, &twin);
        assert!(diff.max_length_error_m.is_nan(), "{diff:?}");
        assert_eq!(diff.non_finite, [(([3, -4], 1), "height_m")]);
        // A GPU seed the twin does not have is flagged too.
        let extra = [record(0, 8.0), record(1, 9.0), record(2, f32::INFINITY)];
        assert_eq!(SeedComparison::of(&extra, &twin).non_finite, [(([3, -4], 2), "height_m")]);
    }
}
