//! How it works: the `[tlm]` table (pass 1), range-checked like the rest of the settings; see
//! `config/default.toml` for what each knob buys and costs.

use serde::Deserialize;

use super::seeds::OcclusionTolerance;
use super::{RangeCheck, SettingsError, first_out_of_range};
use crate::gpu::layout::{TLM_MAX_RINGS, TLM_RADIAL_BANDS};

/// The Tile Load Map (pass 1): camera-centred rings of cells, see `passes::tile_load_map`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TlmSettings {
    /// Edge of a ring-0 cell, metres: the size of a seed pattern and the grain at which tiles are
    /// asked for; ring k's cells are 2^k times larger. See `config/default.toml` `[tlm]`.
    pub cell_m: f64,
    /// Cells per ring side (even, 8 to 256); ring 0 spans `cells × cell_m` metres.
    pub cells: u32,
    /// Most rings (1 to 16); only as many as cover the dataset from the camera are used.
    pub max_rings: u32,
    /// A cell's box is occluded when it lies more than this far behind the terrain; the same
    /// model as `seeds.occlusion_tolerance_*` (`OcclusionTolerance`).
    pub occlusion_tolerance_m: f64,
    /// Part of a cell's occlusion tolerance that grows with distance, metres per km.
    pub occlusion_tolerance_per_km: f64,
    /// The distance bands of ring-0 cells, metres: a cell whose nearest point lies in band k
    /// reads land-cover level k for its seeds; beyond the last, its seeds are not checked.
    pub radial_bands_m: [f64; TLM_RADIAL_BANDS as usize],
    /// Seed patterns P = C⁴ for C corner colours: 1, 16 or 81. Each lattice corner of the ring-0
    /// grid gets one of C colours by a hash of its position, and a cell shows the pattern of its
    /// four corners' colours (`seeds::patterns`), so neighbours agree across their border.
    pub patterns: u32,
    /// The germ of that hash: another value, another (equally deterministic) forest.
    pub seed: u32,
}

/// The pattern counts `tlm.patterns` accepts: C⁴ for C = 1, 2, 3 corner colours.
pub const PATTERN_COUNTS: [u32; 3] = [1, 16, 81];

impl TlmSettings {
    /// Corner colours C of `patterns` = C⁴ (checked by `validate`; 1 for any other value).
    pub fn corner_colours(&self) -> u32 {
        PATTERN_COUNTS.iter().position(|&p| p == self.patterns).map_or(1, |c| c as u32 + 1)
    }

    /// The occlusion tolerance of a cell's box.
    pub fn occlusion(&self) -> OcclusionTolerance {
        OcclusionTolerance { m: self.occlusion_tolerance_m, per_km: self.occlusion_tolerance_per_km }
    }

    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        let r = self.radial_bands_m;
        let checks: [RangeCheck; 7] = [
            (
                self.cell_m.is_finite() && self.cell_m >= 1.0,
                "tlm.cell_m",
                self.cell_m.to_string(),
                "a finite number of metres, at least 1",
            ),
            (
                self.cells.is_multiple_of(2) && (8..=256).contains(&self.cells),
                "tlm.cells",
                self.cells.to_string(),
                "an even number from 8 to 256",
            ),
            (
                (1..=TLM_MAX_RINGS).contains(&self.max_rings),
                "tlm.max_rings",
                self.max_rings.to_string(),
                "1 to 16",
            ),
            (
                self.occlusion_tolerance_m >= 0.0 && self.occlusion_tolerance_m.is_finite(),
                "tlm.occlusion_tolerance_m",
                self.occlusion_tolerance_m.to_string(),
                "0 or more metres",
            ),
            (
                self.occlusion_tolerance_per_km >= 0.0 && self.occlusion_tolerance_per_km.is_finite(),
                "tlm.occlusion_tolerance_per_km",
                self.occlusion_tolerance_per_km.to_string(),
                "0 or more metres per km",
            ),
            (
                r[0] > 0.0 && r.windows(2).all(|w| w[0] <= w[1]) && r.iter().all(|v| v.is_finite()),
                "tlm.radial_bands_m",
                format!("{r:?}"),
                "three increasing positive distances, metres",
            ),
            (
                PATTERN_COUNTS.contains(&self.patterns),
                "tlm.patterns",
                self.patterns.to_string(),
                "C⁴ for C corner colours: 1, 16 or 81 (a cell's pattern is its four corners' colours)",
            ),
        ];
        first_out_of_range(checks)
    }
}
