//! How it works: the texcell pass (Decaudin & Neyret 2004), the forest beyond the last seed band.
//! Dense land-cover classes have a baked forest sample (`crate::texcell`): horizontal slices of a
//! wrapping square of trees, a slice pyramid of fewer, aggregated slices, mips. Each frame the CPU
//! (`frame`) picks the terrain node quadrants the frame draws that reach into the texcell band, far
//! to near, leaves out those with no forest class near them (`dense`: a silhouette's rays reach
//! beyond its quadrant, so a quadrant that draws one stays), and a slice pyramid level for each
//! from its distance; every slice of every such patch is one instance of the quadrant's grid,
//! lifted off the ground it follows, drawn far patch first and within a patch the slice farthest
//! from the eye's height first. The shader (`shaders/texcells.wgsl`, `gpu`) shows forest only where
//! the land cover under a fragment is a dense class, maps the sample aperiodically over the ground
//! (eight edge-compatible tiles chosen by hashed edge colours, `texcell::tiling`), corrects each
//! slice's opacity for the oblique path between slices, lights it with the ground's sun and tints
//! it with the imagery under it, and dithers it in where the last billboard clouds dither out.
//! Where the view grazes the canopy (`texcells.silhouette_deg`), a patch also draws its slab's top
//! face once, whose fragments march their ray through the samples' 3D texture (the paper's
//! silhouette texcells), the two kinds sharing the patch's pixels by a dither on each ray's angle
//! below the horizon.

pub mod dense;
pub mod frame;
pub mod gpu;

use std::path::PathBuf;

use thiserror::Error;

use crate::texcell::TexcellError;

/// Why the texcell pass could not be set up.
#[derive(Debug, Error)]
pub enum TexcellsError {
    /// A dense class's forest sample could not be read.
    #[error(transparent)]
    Sample(#[from] TexcellError),
    /// The pass was asked for without any forest sample.
    #[error("no forest sample to draw texcells with")]
    NoSamples,
    /// The samples were baked with different sizes or slice counts; one texture array holds them.
    #[error(
        "{path}: {texels} texels and {slices} slices, unlike the first sample's {first_texels} and {first_slices}: bake the classes' samples with the same options"
    )]
    Mismatch {
        /// The sample's folder.
        path: PathBuf,
        /// Its texels and slices.
        texels: u32,
        /// Its finest slice count.
        slices: u32,
        /// The first sample's texels.
        first_texels: u32,
        /// The first sample's finest slice count.
        first_slices: u32,
    },
    /// More samples, or more of their slices, than the texture array or the table holds.
    #[error("{layers} texture layers of forest slices; this adapter holds at most {max}")]
    TooManyLayers {
        /// Layers the samples need.
        layers: u32,
        /// The adapter's limit (or the pass's: `TEXCELL_MAX_SAMPLES` · `TEXCELL_MAX_SLICES`).
        max: u32,
    },
}
