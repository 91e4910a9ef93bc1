//! How it works: compares two seed sets by identity (cell address, rank), whatever their order:
//! which seeds only one side has, which common ones disagree on what they are (species, LOD,
//! levels, jitter), and how far their lengths and ground colours differ.

use std::collections::{HashMap, HashSet};

use crate::gpu::gpu_types::SeedRecord;

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
    /// Largest difference of position, height, radius or ground height, metres.
    pub max_length_error_m: f32,
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
        for t in twin {
            let Some(g) = gpu_by_key.get(&key(t)) else {
                out.only_twin.push(key(t));
                continue;
            };
            out.common += 1;
            if (g.species_lod, g.jitter) != (t.species_lod, t.jitter) {
                out.mismatched.push(key(t));
            }
            let lengths = [
                (g.position_rel_m[0], t.position_rel_m[0]),
                (g.position_rel_m[1], t.position_rel_m[1]),
                (g.position_rel_m[2], t.position_rel_m[2]),
                (g.height_m, t.height_m),
                (g.radius_m, t.radius_m),
                (g.ground_m, t.ground_m),
            ];
            for (a, b) in lengths {
                out.max_length_error_m = out.max_length_error_m.max((a - b).abs());
            }
            for c in 0..4 {
                let channel = |w: u32| (w >> (8 * c)) & 0xff;
                out.max_colour_error =
                    out.max_colour_error.max(channel(g.ground_colour).abs_diff(channel(t.ground_colour)));
            }
        }
        out.only_gpu = gpu.iter().map(key).filter(|k| !twin_keys.contains(k)).collect();
        out
    }
}
