//! What one frame did (`FrameReport`): the terrain's nodes, the caches' streaming, the Tile Load
//! Map's and pass 3's latest results, the foliage's fragments and the frame's counts.

use crate::gpu::counts::FrameCounts;
use crate::gpu::fragments::PassFragments;
use crate::streaming::CacheStats;

use super::{SeedReport, TexcellReport};

/// What one frame did, for logs and tests.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameReport {
    /// Index of this frame since the renderer was made, from 0.
    pub frame: u64,
    /// Terrain nodes drawn, each one instance over its height tile or a resident ancestor's.
    pub nodes_drawn: usize,
    /// Nodes selected but not drawn because their height tile did not fit or could not be read.
    pub nodes_dropped: usize,
    /// The height cache's streaming this frame.
    pub height: CacheStats,
    /// The imagery cache's streaming this frame (all zero without imagery).
    pub imagery: CacheStats,
    /// The land-cover cache's streaming this frame (all zero without land cover).
    pub landcover: CacheStats,
    /// The frame whose Tile Load Map drove this frame's streaming (`None` before the first one
    /// arrives).
    pub tlm_frame: Option<u64>,
    /// Cells that Tile Load Map found visible (0 before the first one arrives).
    pub tlm_visible_cells: usize,
    /// Distinct seed patterns that Tile Load Map's cells use.
    pub tlm_patterns: usize,
    /// TLM readbacks skipped so far because every staging buffer was still in flight.
    pub tlm_readbacks_skipped: u64,
    /// Ring-0 cells whose seeds this frame checks.
    pub seed_cells: usize,
    /// Near, visible cells left out of pass 3 because they were beyond its dispatch limit.
    pub seed_cells_dropped: usize,
    /// Pass 3's counters of the latest frame whose counters have arrived (a frame or two old).
    pub seeds: Option<SeedReport>,
    /// Species (each variant counted: each of `ClassTable::species`) drawn with an impostor.
    pub seed_species_drawn: usize,
    /// Species selected but not drawn (no `draw_seeds.impostors`, or no model for them).
    pub seed_species_undrawn: usize,
    /// Metres the camera was lifted by because it was under the ground (0 when it was not).
    pub camera_lifted_m: f64,
    /// The far forest's patches and slices (all zero without texcells).
    pub texcells: TexcellReport,
    /// Per foliage pass, fragments shaded and pixels covered (only with `gpu.count_fragments`).
    pub fragments: Vec<PassFragments>,
    /// The counts of every frame whose counts arrived during this one (a frame or two old; this
    /// frame's own with `gpu.count_fragments`, which waits for each frame).
    pub counts: Vec<FrameCounts>,
}
