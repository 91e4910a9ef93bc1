//! How it works: pass 4b, drawing the seeds (DESIGN § "The frame", step 4). Everything a species
//! looks like is uploaded once, at `new` (`assets`): its real mesh and its billboard clouds of 17,
//! 8 and 2 planes in one vertex and one index buffer, every texture (cloud atlases, mesh textures)
//! as a layer of one RGBA8 sRGB texture array, and a material table the vertices index. The draw
//! group of (species, LOD) gets its index range as a compaction template (`templates`, for
//! `CompactPass::set_templates`), and its cross-fade draw the next LOD's range.
//!
//! Each frame `encode` records two `draw_indexed_indirect`s per group from compaction's argument
//! buffer (an empty group costs nothing): its own, and the same instances with the next LOD's
//! geometry; LOD by LOD, and each draw's instances near to far (pass 3 checks its cells nearest
//! first and compaction keeps that order), so nearer crowns' depth hides what is behind them early.
//! With `draw_seeds.depth_prepass` every draw is first made writing depth alone (`fs_depth`: the
//! alpha test and dithers), then again testing depth for equality, so only the fragment a pixel
//! shows is lit; the pixels are the same either way. `shaders/draw_seeds.wgsl` reads an
//! instance's record through compaction's `order`, scales the model to the seed's height, turns it
//! by the seed's jitter, places it camera-relative and projects it with the terrain's matrix; it draws into the colour target with the terrain
//! depth (reversed-Z, `GreaterEqual`, depth written). A seed in the outer `seeds.fade_fraction`
//! of its LOD's reach cross-fades: its own geometry keeps the pixels whose (per-seed shifted)
//! Bayer threshold is below the fade, the next LOD's geometry the others, so each pixel shows
//! exactly one of the two and nothing pops; outside the band the cross-fade draw collapses its
//! vertices. The last LOD fades out to nothing at the visibility radius. With `draw_seeds.samples`
//! at 4 the groups are drawn multisampled instead (`shaders/draw_seeds/multisample.wgsl`), each
//! fragment covering as many of its pixel's samples as its alpha says, and resolved into the frame
//! (`gpu::multisample`).
//!
//! `frame` (the frame's constants, the impostors loaded from a folder) and `assets` (their layout
//! for one upload) are the CPU half; `gpu` the pipeline, binding table, uploads and draws.

pub mod assets;
pub mod frame;
pub mod from_above;
pub mod gpu;

use std::path::PathBuf;

use thiserror::Error;

use crate::gpu::layout::SEED_LODS;
use crate::impostor::ImpostorError;

pub use assets::{LodChoices, MAX_LAYER_TEXELS};

/// Why the species' impostors could not be loaded, laid out or uploaded for the seed draw.
#[derive(Debug, Error)]
pub enum DrawSeedsError {
    /// The impostor folder (`seeds.impostors`) given is not a directory.
    #[error("seeds.impostors = {0:?} is not a folder (bake one with `terramp-data bake`)")]
    NoFolder(PathBuf),
    /// A model the class table names is in the folder but could not be read.
    #[error(transparent)]
    Impostor(#[from] ImpostorError),
    /// An impostor was baked with fewer billboard clouds than draw LODs 1 to 3 need.
    #[error("impostor {model:?} has {lods} billboard-cloud LODs; the seed draw needs {}", SEED_LODS - 1)]
    TooFewLods {
        /// The model's name, as the class table gives it.
        model: String,
        /// Billboard-cloud LODs it has.
        lods: usize,
    },
    /// The adapter lacks `INDIRECT_FIRST_INSTANCE`, which every group's draw needs to start at its
    /// slots of the permutation.
    #[error("this GPU cannot start indirect draws at an instance (INDIRECT_FIRST_INSTANCE): no seeds")]
    NoFirstInstance,
    /// The atlases and mesh textures take more layers than the device's texture arrays hold.
    #[error("{layers} atlas layers; this GPU holds at most {max} in a texture array")]
    TooManyLayers {
        /// Layers the species need.
        layers: u32,
        /// The device's `max_texture_array_layers`.
        max: u32,
    },
}

#[cfg(test)]
mod tests;
