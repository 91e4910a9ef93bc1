//! How it works: the Tile Load Map (pass 1, Amara et al. 2007 § 4.2) tells the CPU, per cell of
//! a regular grid over the ground, whether the view needs it and at which levels. The grid is a
//! set of camera-centred rings (clipmap-like, so one layout serves a 15 km dataset and a planet):
//! ring k has `cells`² cells of edge `cell_m · 2^k`, and its origin snaps to *two* of its cells,
//! so that ring k − 1's square is exactly a block of ring-k cells (those write 0: ring k − 1
//! speaks for them) and a cell of ring k is always the same square of ground, its global address
//! (k, gx, gy) covering [gx · c_k, (gx + 1) · c_k] × [gy · c_k, (gy + 1) · c_k] of grid space.
//! Only as many rings as cover the dataset from the camera are used (at most `max_rings`).
//!
//! `TlmLayout` is that geometry, in f64, shared by the GPU pass, its CPU twin and the CPU
//! analysis. Each frame the CPU turns it into per-column and per-row `TlmSpan`s (extent clamped to
//! the dataset and relative to the camera, height tiles overlapped, inside/covered flags): all
//! the large-coordinate and floor/ceil work happens here in f64, and the shader only combines a
//! column with a row. The shader (`shaders/tile_load_map.wgsl`) then culls the cell's box (its
//! extent × the union of its height tiles' ranges) against the frustum and the depth pyramid,
//! and derives the imagery, terrain and radial levels from its nearest and farthest points.
//!
//! `layout` (the rings), `frame` (the frame's uniforms and spans) and `analysis` (the readback
//! turned into load maps and seed cells) are the CPU half, which streaming's callers and the twin
//! (`reference::tile_load_map`) read; `gpu` the pipeline, binding table and recorded dispatch.

pub mod analysis;
pub mod frame;
pub mod gpu;
pub mod layout;

use thiserror::Error;

use crate::camera::CameraError;
use crate::gpu::layout::MAX_LEVELS;

/// Why a frame's Tile Load Map could not be computed or dispatched.
#[derive(Debug, Error)]
pub enum TlmError {
    /// The camera has no projection for the viewport.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// The dataset's height pyramid has more levels (or LODs) than `MAX_LEVELS`.
    #[error("the TLM supports at most {MAX_LEVELS} height levels; this dataset has {0}")]
    TooManyLevels(u32),
    /// A frame's layout has more rings, or another number of cells per side, than the pass was built for.
    #[error(
        "the layout has {rings} rings of {cells}² cells; the pass was built for {max_rings} of {pass_cells}²"
    )]
    LayoutMismatch {
        /// Rings of the frame's layout.
        rings: u32,
        /// Cells per ring side in the frame's layout.
        cells: u32,
        /// Rings the pass was built for.
        max_rings: u32,
        /// Cells per ring side the pass was built for.
        pass_cells: u32,
    },
}
