//! How it works: every way making a renderer or running a frame can fail, one enum, each variant
//! saying what to change (the setting, the dataset, the adapter) in its message.

use thiserror::Error;

use crate::camera::CameraError;
use crate::dataset::PackError;
use crate::gpu::GpuError;
use crate::gpu::layout::MAX_LEVELS;
use crate::passes::tile_load_map::TlmError;
use crate::streaming::LoaderError;

/// Why a renderer could not be made, or a frame (or a tool's readback) could not run.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The GPU failed: an error scope caught something, or a wait or a readback failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The camera (a coordinate, its field of view or near plane) or the viewport is out of range.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// A tile pack could not be read, as when a tool snapshots the caches for a CPU twin.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// The imagery pyramid is deeper than the levels the shaders' per-level tables hold.
    #[error("the dataset has {levels} imagery levels; at most {MAX_LEVELS} are supported")]
    TooManyLevels {
        /// Levels of the dataset's imagery pyramid.
        levels: u32,
    },
    /// The tile loader could not start its threads, or lacks a layer it was asked for.
    #[error(transparent)]
    Loader(#[from] LoaderError),
    /// The Tile Load Map cannot cover this dataset or view: too many height levels, rings that do
    /// not fit its pass, or a camera it cannot project.
    #[error(transparent)]
    Tlm(#[from] TlmError),
    /// The land cover's class table (its scheme's, or `seeds.class_table`) could not be loaded.
    #[error(transparent)]
    ClassTable(#[from] crate::classes::ClassTableError),
    /// The species tables cannot be built from the class table: a class too dense for the
    /// patterns, or too many species.
    #[error(transparent)]
    Seeds(#[from] crate::seeds::SeedError),
    /// Compaction does not fit this adapter (too many blocks, a buffer too large for one binding),
    /// or its readback found a bad block.
    #[error(transparent)]
    Compact(#[from] crate::passes::compact::CompactError),
    /// The texcell pass could not be set up: a forest sample unreadable, samples of different
    /// shapes, or more than the texture array holds.
    #[error(transparent)]
    Texcells(#[from] crate::passes::texcells::TexcellsError),
    /// Pass 4 could not be set up: `draw_seeds.impostors` missing or unreadable, an impostor short
    /// of LODs, or an adapter without the features it needs.
    #[error(transparent)]
    DrawSeeds(#[from] crate::passes::draw_seeds::DrawSeedsError),
    /// The exact oracle could not judge the plants near a point (`Renderer::plants_near`): a
    /// camera it cannot project, a pack it cannot read.
    #[error(transparent)]
    Oracle(#[from] crate::reference::oracle::OracleError),
    /// A host's targets cannot be drawn over (`Renderer::render_into`).
    #[error(transparent)]
    Host(#[from] super::HostTargetError),
    /// The device allows less than terramp's passes need (a device the host made).
    #[error(transparent)]
    Limits(#[from] crate::passes::limits::LimitShort),
    /// `render.sun_time` cannot place the sun: a time it cannot read, or a dataset that does not
    /// record where it lies on the Earth.
    #[error(transparent)]
    Sun(#[from] crate::sun::SunError),
    /// `gpu.count_fragments` is on and a frame was to be recorded into a host's encoder: the
    /// counter waits for each frame, and a frame the host submits cannot be waited for.
    #[error(
        "gpu.count_fragments waits for each frame: turn it off to record into the host's encoder, or draw with render_into"
    )]
    FragmentsWait,
    /// `gpu.count_fragments` is on, and the adapter has no pipeline-statistics queries.
    #[error("gpu.count_fragments: this adapter cannot count fragments (no pipeline-statistics queries)")]
    NoFragmentCounts,
    /// `seeds.capacity` asks for a record buffer larger than this adapter can bind at once.
    #[error("seeds.capacity = {capacity} records does not fit one GPU buffer binding here (at most {max})")]
    SeedCapacity {
        /// Records asked for by `seeds.capacity`.
        capacity: u32,
        /// Most records one storage-buffer binding of this adapter holds.
        max: u32,
    },
    /// `pin_everything` was asked of a layer with more tiles than its cache has slots.
    #[error("the {layer} cache has {slots} slots; the whole layer is {tiles} tiles")]
    DoesNotFit {
        /// The layer that does not fit: `height`, `imagery` or `land-cover`.
        layer: &'static str,
        /// Tiles in the whole layer, all levels.
        tiles: u64,
        /// Slots of the layer's cache (`cache.*_slots`).
        slots: usize,
    },
    /// `Renderer::render_resolved` rendered `frames` frames and the view still had tiles to load:
    /// a reader or the GPU is stuck.
    #[error("the view did not resolve in {frames} frames: tiles still loading (a stuck reader?)")]
    Unresolved {
        /// Frames rendered.
        frames: u32,
    },
    /// A `cache.*_slots` asks for more tiles than this adapter's texture arrays hold.
    #[error(
        "cache.{key} = {slots} slots is more than this adapter's texture arrays hold (at most {max} layers)"
    )]
    CacheTooLarge {
        /// The setting: `height_slots`, `imagery_slots` or `landcover_slots`.
        key: &'static str,
        /// Slots asked for.
        slots: u32,
        /// The device's `max_texture_array_layers`.
        max: u32,
    },
    /// `render.width` or `render.height` exceeds the adapter's largest 2D texture.
    #[error("a {width}×{height} viewport is larger than this adapter's {max}-pixel targets")]
    ViewportTooLarge {
        /// Viewport width asked for, pixels.
        width: u32,
        /// Viewport height asked for, pixels.
        height: u32,
        /// The adapter's largest texture side, pixels.
        max: u32,
    },
}
