//! How it works: `Renderer` owns the GPU resources of one dataset (caches, loader threads, passes,
//! targets) and `render` runs one frame in three steps: `prepare` does the frame's CPU work (the
//! terrain's LOD selection, the streaming the latest Tile Load Map asked for, every upload of the
//! frame), `encode` records the paper's passes, one line each, and `submit` sends them with the
//! non-blocking readbacks and takes whatever earlier readbacks have arrived. Nothing in a frame
//! waits for the disk or the GPU: tiles stream in over the following frames, and until they do
//! their ancestors stand in; the Tile Load Map and pass 3's counters come back a frame or two late.

use std::sync::Arc;

use glam::DVec3;
use thiserror::Error;

use crate::camera::{Camera, CameraError};
use crate::config::Settings;
use crate::dataset::{Dataset, PackError, TileId};
use crate::gpu::layout::MAX_LEVELS;
use crate::gpu::readback_ring::{DEFAULT_SLOTS, ReadbackRing};
use crate::gpu::{Gpu, GpuError, PassTiming, Profiler};
use crate::passes::depth_pyramid::gpu::DepthPyramid;
use crate::passes::ground::gpu::GroundPass;
use crate::passes::terrain::gpu::{MeshDraw, PreparedNodes, TerrainPass};
use crate::passes::terrain::select::NodeBounds;
use crate::passes::tile_load_map::TlmError;
use crate::passes::tile_load_map::analysis::{LoadMaps, analyse};
use crate::passes::tile_load_map::frame::{TlmFrame, height_tile_ranges};
use crate::passes::tile_load_map::gpu::{TileLoadMapPass, TlmBindings};
use crate::passes::tile_load_map::layout::TlmLayout;
use crate::streaming::{CacheStats, Loader, LoaderError, TileCache};

mod clearance;
mod prepare;
mod seeds;
mod setup;
mod tools;

pub use clearance::GROUND_CLEARANCE_NEAR;
pub use seeds::SeedReport;
pub use tools::Replay;

/// Linear-RGB colour of the sky, also the haze the distance fades into.
const SKY_LINEAR: [f64; 3] = [0.42, 0.55, 0.75];

#[derive(Debug, Error)]
pub enum RenderError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error(transparent)]
    Pack(#[from] PackError),
    #[error("the dataset has {levels} imagery levels; at most {MAX_LEVELS} are supported")]
    TooManyLevels { levels: u32 },
    #[error(transparent)]
    Loader(#[from] LoaderError),
    #[error(transparent)]
    Tlm(#[from] TlmError),
    #[error(transparent)]
    ClassTable(#[from] crate::classes::ClassTableError),
    #[error(transparent)]
    Seeds(#[from] crate::seeds::SeedError),
    #[error(transparent)]
    Compact(#[from] crate::passes::compact::CompactError),
    #[error(transparent)]
    DrawSeeds(#[from] crate::passes::draw_seeds::DrawSeedsError),
    #[error("seeds.capacity = {capacity} records does not fit one GPU buffer binding here (at most {max})")]
    SeedCapacity { capacity: u32, max: u32 },
    #[error("the {layer} cache has {slots} slots; the whole layer is {tiles} tiles")]
    DoesNotFit { layer: &'static str, tiles: u64, slots: usize },
    #[error("a {width}×{height} viewport is larger than this adapter's {max}-pixel targets")]
    ViewportTooLarge { width: u32, height: u32, max: u32 },
}

/// What one frame did, for logs and tests.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameReport {
    pub frame: u64,
    pub nodes_drawn: usize,
    /// Nodes selected but not drawn because their height tile did not fit or could not be read.
    pub nodes_dropped: usize,
    pub height: CacheStats,
    pub imagery: CacheStats,
    pub landcover: CacheStats,
    /// The frame whose Tile Load Map drove this frame's streaming (`None` before the first one
    /// arrives), its visible cells and the seed patterns it uses.
    pub tlm_frame: Option<u64>,
    pub tlm_visible_cells: usize,
    pub tlm_patterns: usize,
    /// TLM readbacks skipped so far because every staging buffer was still in flight.
    pub tlm_readbacks_skipped: u64,
    /// Ring-0 cells whose seeds this frame checks (and how many beyond the dispatch limit were
    /// left out).
    pub seed_cells: usize,
    pub seed_cells_dropped: usize,
    /// Pass 3's counters of the latest frame whose counters have arrived (a frame or two old).
    pub seeds: Option<SeedReport>,
    /// Species drawn with an impostor, and species not drawn (no `seeds.impostors`, or no model).
    pub seed_species_drawn: usize,
    pub seed_species_undrawn: usize,
    /// Metres the camera was lifted by because it was under the ground (0 when it was not).
    pub camera_lifted_m: f64,
}

/// What a frame's Tile Load Map is read against when it comes back: the frame, its rings and
/// where the camera was.
struct TlmTag {
    frame: u64,
    layout: TlmLayout,
    camera_grid_m: DVec3,
}

/// What the last frame recorded, kept (not copied) for tools that read or replay it.
struct LastFrame {
    tlm: TlmFrame,
    nodes: PreparedNodes,
}

/// The three tile caches, with the tiles each keeps resident for good.
struct Caches {
    heights: TileCache,
    imagery: TileCache,
    /// `None` without land cover.
    landcover: Option<TileCache>,
    /// The coarsest tiles of each layer, resident from the first frame on and never evicted (all
    /// of them after `pin_everything`; no land cover otherwise: seeds only live near the camera).
    pinned_heights: Vec<TileId>,
    pinned_imagery: Vec<TileId>,
    pinned_landcover: Vec<TileId>,
}

/// The frame's render targets and their views, made once.
struct Targets {
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    colour_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
}

pub struct Renderer {
    pub gpu: Gpu,
    pub dataset: Arc<Dataset>,
    pub settings: Settings,
    pub profiler: Profiler,
    terrain: TerrainPass,
    terrain_bindings: wgpu::BindGroup,
    ground: GroundPass,
    depth_pyramid: DepthPyramid,
    tlm: TileLoadMapPass,
    tlm_bindings: TlmBindings,
    tlm_readback: ReadbackRing<TlmTag>,
    /// Pass 3 and 4 and what they need; `None` without land cover.
    seeds: Option<seeds::SeedStage>,
    caches: Caches,
    loader: Loader,
    targets: Targets,
    /// Height ranges of terrain nodes, read from the packs once and kept.
    bounds: NodeBounds,
    /// The latest TLM's load maps; they drive the streaming of the next frames.
    load_maps: Option<LoadMaps>,
    last: Option<LastFrame>,
    frame: u64,
    /// Pass timings of the most recent frame whose timings are in (a frame or two behind).
    last_timings: Vec<PassTiming>,
}

impl Renderer {
    pub fn new(gpu: Gpu, dataset: Dataset, settings: Settings) -> Result<Self, RenderError> {
        let dataset = Arc::new(dataset);
        let targets = Targets::new(&gpu.device, &settings)?;
        let device = &gpu.device;
        let terrain = TerrainPass::new(device, &settings);
        let software = gpu.info.device_type == wgpu::DeviceType::Cpu;
        let ground = GroundPass::new(device, &settings, software, &terrain);
        let caches = Caches::new(&gpu, &dataset, &settings)?;
        let loader = Loader::new(Arc::clone(&dataset), settings.cache.loader_threads as usize)?;
        let depth_pyramid = DepthPyramid::new(device, settings.render.width, settings.render.height);
        let tlm = TileLoadMapPass::new(device, &settings);
        let tlm_bindings = tlm.bind_group(device, &height_tile_ranges(&dataset), &depth_pyramid);
        let tlm_readback = ReadbackRing::new(device, "tile load map", tlm.capacity_bytes(), DEFAULT_SLOTS);
        let terrain_bindings = terrain.bind_group(device, &caches.heights, &caches.imagery, ground.sampler());
        let seeds = seeds::SeedStage::new(&gpu, &dataset, &settings, &caches, &targets.depth_view)?;
        let h = &dataset.manifest.height;
        let bounds = NodeBounds::new([h.min_m, h.max_m]);
        let profiler = Profiler::new(&gpu, settings.gpu.timestamps);
        Ok(Self {
            gpu,
            dataset,
            settings,
            profiler,
            terrain,
            terrain_bindings,
            ground,
            depth_pyramid,
            tlm,
            tlm_bindings,
            tlm_readback,
            seeds,
            caches,
            loader,
            targets,
            bounds,
            load_maps: None,
            last: None,
            frame: 0,
            last_timings: Vec::new(),
        })
    }

    /// Pass timings of the latest frame whose timings have arrived (never blocks for them).
    pub fn last_timings(&self) -> &[PassTiming] {
        &self.last_timings
    }

    /// The terrain's reversed-Z depth of the last frame (1 near, 0 at infinity), for later passes.
    pub fn depth_texture(&self) -> &wgpu::Texture {
        &self.targets.depth
    }

    /// Renders one frame from `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<FrameReport, RenderError> {
        camera.validate()?;
        let (camera, camera_lifted_m) = self.above_ground(camera);
        let mut report = FrameReport { frame: self.frame, camera_lifted_m, ..Default::default() };
        let plan = self.prepare(&camera, &mut report)?;
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.encode(&mut encoder, &plan.nodes, &plan.tlm)?;
        self.submit(encoder, plan, &mut report)?;
        Ok(report)
    }

    /// Records the frame's passes, in the paper's order.
    fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        nodes: &PreparedNodes,
        tlm: &TlmFrame,
    ) -> Result<(), RenderError> {
        let (gpu, p, t) = (&self.gpu, &mut self.profiler, &self.targets);
        let mesh = MeshDraw { terrain: &self.terrain, bind_group: &self.terrain_bindings, nodes };
        // 0. Terrain and depth: the ground every later pass stands on and is occluded by.
        p.pass(gpu, encoder, "terrain", |e| {
            self.terrain.encode(e, &self.terrain_bindings, &t.depth_view, nodes)
        })?;
        // The depth pyramid: the occluders the Tile Load Map culls against, at every scale.
        p.pass(gpu, encoder, "depth_pyramid", |e| self.depth_pyramid.encode(e, &t.depth_view))?;
        // 1. Tile Load Map: which tiles at which levels the view needs, and the seed patterns.
        p.pass(gpu, encoder, "tile_load_map", |e| self.tlm.encode(e, &self.tlm_bindings, tlm))?;
        // 2. Ground: imagery on the surface the depth pass kept, from the finest resident level.
        p.pass(gpu, encoder, "ground", |e| {
            self.ground.encode(e, mesh, &t.colour_view, &t.depth_view, SKY_LINEAR)
        })?;
        if let Some(stage) = &self.seeds {
            // 3. Seed selection: the seeds of the cells the latest TLM found near and visible.
            p.pass(gpu, encoder, "seed_select", |e| stage.encode(e))?;
            // 4a. Compaction: the survivors grouped per (species, LOD) into indirect draws, on the GPU.
            p.pass(gpu, encoder, "compact", |e| stage.encode_compact(e))?;
            // 4b. Drawing: one indirect draw per group, over the ground, depth-tested against it.
            p.pass(gpu, encoder, "draw_seeds", |e| stage.encode_draw(e, &t.colour_view, &t.depth_view))?;
        }
        Ok(())
    }

    /// Records the frame's readbacks (after the last timed pass: the CPU-timing fallback submits
    /// each pass's encoder on its own), submits, and takes every readback that has arrived.
    fn submit(
        &mut self,
        mut encoder: wgpu::CommandEncoder,
        plan: prepare::FramePlan,
        report: &mut FrameReport,
    ) -> Result<(), RenderError> {
        let prepare::FramePlan { layout, camera_grid_m, tlm, nodes } = plan;
        let tag = TlmTag { frame: self.frame, layout, camera_grid_m };
        self.tlm_readback.encode_copy(&mut encoder, self.tlm.output(), tlm.output_bytes(), tag);
        if let Some(stage) = self.seeds.as_mut() {
            stage.encode_readback(&mut encoder, self.frame);
        }
        self.profiler.resolve(&mut encoder);
        self.gpu.queue.submit([encoder.finish()]);
        self.tlm_readback.submitted();
        if let Some(stage) = self.seeds.as_mut() {
            stage.submitted();
        }
        self.profiler.end_frame();
        self.gpu.device.poll(wgpu::PollType::Poll).map_err(GpuError::from)?;
        self.analyse_arrived_tlms()?;
        report.tlm_readbacks_skipped = self.tlm_readback.skipped();
        if let Some(stage) = self.seeds.as_mut() {
            stage.collect(&self.gpu.device)?;
            report.seeds = stage.latest;
        }
        while let Some(timings) = self.profiler.finished_frame(&self.gpu) {
            self.last_timings = timings;
        }
        self.gpu.check()?;
        self.last = Some(LastFrame { tlm, nodes });
        self.frame += 1;
        Ok(())
    }

    /// Turns every TLM that has arrived into load maps, keeping the newest.
    fn analyse_arrived_tlms(&mut self) -> Result<(), RenderError> {
        while let Some(readback) = self.tlm_readback.try_take(&self.gpu.device)? {
            let TlmTag { frame, layout, camera_grid_m } = &readback.tag;
            let cells = readback.cast();
            let dataset = &self.dataset;
            let maps = self
                .profiler
                .cpu("tlm_analysis", || analyse(*frame, layout, &cells, *camera_grid_m, dataset));
            self.load_maps = Some(maps);
        }
        Ok(())
    }
}
