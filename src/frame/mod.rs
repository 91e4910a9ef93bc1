//! How it works: `Renderer` owns the GPU resources of one dataset (caches, loader threads, passes,
//! targets) and `render` runs one frame as the list of its steps. Each step says why it is there;
//! the mechanics live in the pass and streaming modules. Nothing in a frame waits for the disk:
//! tiles stream in over the following frames, and until they do their ancestors stand in.

use std::collections::VecDeque;
use std::sync::Arc;

use glam::DVec3;
use thiserror::Error;

use crate::camera::{Camera, CameraError, Frustum};
use crate::config::Settings;
use crate::dataset::{Dataset, IMAGERY_MIPS, LayerSpec, PackError, TileId};
use crate::gpu::readback_ring::{DEFAULT_SLOTS, ReadbackRing};
use crate::gpu::{Gpu, GpuError, PassTiming, Profiler};
use crate::passes::depth_pyramid::DepthPyramid;
use crate::passes::ground::GroundPass;
use crate::passes::seed_select::SeedSources;
use crate::passes::tile_load_map::{
    TileLoadMapPass, TlmBindings, TlmError, TlmFrame, TlmImagery, TlmInputs, TlmLayout, height_tile_ranges,
};
use crate::shaders::MAX_LEVELS;
use crate::streaming::analysis::{LoadMaps, analyse};
use crate::streaming::wants::{after_pinned, height_tiles, pinned_tiles};
use crate::streaming::{CacheStats, LayerKind, Loader, LoaderError, TileCache, UploadBudget};
use crate::terrain::select::{Lods, NodeBounds, select};
use crate::terrain::{
    COLOUR_FORMAT, DEPTH_FORMAT, MeshDraw, PreparedNodes, TerrainPass, node_batches, terrain_uniforms,
};

mod clearance;
mod seeds;
mod tools;

pub use clearance::GROUND_CLEARANCE_NEAR;

pub use seeds::SeedReport;
pub use tools::Replay;

/// Tiles of the coarsest levels each cache keeps resident from the start, at most: the three
/// coarsest levels of a square layer (1 + 4 + 16), a fallback everywhere at a quarter of the
/// finest pinned detail, for a few MiB.
const MAX_PINNED_TILES: usize = 21;

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

pub struct Renderer {
    pub gpu: Gpu,
    pub dataset: Arc<Dataset>,
    pub settings: Settings,
    pub profiler: Profiler,
    terrain: TerrainPass,
    ground: GroundPass,
    heights: TileCache,
    imagery: TileCache,
    /// The coarsest tiles of each layer, resident from the first frame on and never evicted.
    pinned_heights: Vec<TileId>,
    pinned_imagery: Vec<TileId>,
    /// Land-cover tiles pinned by `pin_everything` (none otherwise: seeds only live near the camera).
    pinned_landcover: Vec<TileId>,
    landcover: Option<TileCache>,
    /// Pass 3 and what it needs; `None` without land cover.
    seeds: Option<seeds::SeedStage>,
    loader: Loader,
    depth_pyramid: DepthPyramid,
    tlm: TileLoadMapPass,
    tlm_bindings: TlmBindings,
    tlm_readback: ReadbackRing,
    /// Layouts of the TLMs in flight, by frame: a TLM is read against its own frame's layout.
    tlm_layouts: VecDeque<(u64, TlmLayout, DVec3)>,
    /// The last frame's TLM inputs, to read its output back (`read_tile_load_map`), and its
    /// terrain nodes, to replay its depth (`replay_seed_passes`).
    last_tlm: Option<TlmFrame>,
    last_nodes: Option<PreparedNodes>,
    /// The latest TLM's load maps; they drive the streaming of the next frames.
    load_maps: Option<LoadMaps>,
    terrain_bindings: wgpu::BindGroup,
    bounds: NodeBounds,
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    frame: u64,
    /// Pass timings of the most recent frame whose timings are in (a frame or two behind).
    last_timings: Vec<PassTiming>,
}

impl Renderer {
    pub fn new(gpu: Gpu, dataset: Dataset, settings: Settings) -> Result<Self, RenderError> {
        let dataset = Arc::new(dataset);
        let device = &gpu.device;
        // Targets of no area, or wider than the adapter allows, would only fail later as GPU errors.
        let (width, height, max) =
            (settings.render.width, settings.render.height, device.limits().max_texture_dimension_2d);
        if width == 0 || height == 0 {
            return Err(CameraError::Viewport(width, height).into());
        }
        if width.max(height) > max {
            return Err(RenderError::ViewportTooLarge { width, height, max });
        }
        let terrain = TerrainPass::new(device, &settings);
        let software = gpu.info.device_type == wgpu::DeviceType::Cpu;
        let ground = GroundPass::new(device, &settings, software, &terrain);
        let heights = TileCache::new(
            device,
            "height cache",
            LayerKind::Height,
            dataset.height.pyramid,
            1,
            wgpu::TextureFormat::R32Float,
            settings.cache.height_slots,
        );
        let imagery = match &dataset.imagery {
            Some(layer) if layer.pyramid.levels > MAX_LEVELS => {
                return Err(RenderError::TooManyLevels { levels: layer.pyramid.levels });
            }
            Some(layer) => TileCache::new(
                device,
                "imagery cache",
                LayerKind::Imagery,
                layer.pyramid,
                layer.mips,
                wgpu::TextureFormat::Rgba8UnormSrgb,
                settings.cache.imagery_slots,
            ),
            // The shader reads imagery through the same bindings either way; a one-slot cache
            // that stays empty costs 1.5 MiB and keeps one code path.
            None => TileCache::new(
                device,
                "no imagery",
                LayerKind::Imagery,
                LayerSpec::imagery([1, 1]).pyramid,
                IMAGERY_MIPS,
                wgpu::TextureFormat::Rgba8UnormSrgb,
                1,
            ),
        };
        let mut heights = heights;
        let mut imagery = imagery;
        // Pinned tiles load now, synchronously: they are what every later frame falls back on.
        let pin =
            |cache: &TileCache| pinned_tiles(cache.pyramid(), MAX_PINNED_TILES.min(cache.capacity() / 4));
        let pinned_heights = pin(&heights);
        heights.load_now(&gpu.queue, &pinned_heights, 0, |id| dataset.height.tile_bytes(id));
        let pinned_imagery = match &dataset.imagery {
            Some(layer) => {
                let pinned = pin(&imagery);
                imagery.load_now(&gpu.queue, &pinned, 0, |id| layer.tile_bytes(id));
                pinned
            }
            None => Vec::new(),
        };
        let landcover = match (&dataset.landcover, &dataset.manifest.landcover) {
            (Some(layer), Some(meta)) => Some(TileCache::new(
                device,
                "land-cover cache",
                LayerKind::Landcover,
                layer.pyramid,
                1,
                meta.coding.texture_format(),
                settings.cache.landcover_slots,
            )),
            _ => None,
        };
        let loader = Loader::new(Arc::clone(&dataset), settings.cache.loader_threads as usize)?;
        let depth_pyramid = DepthPyramid::new(device, settings.render.width, settings.render.height);
        let tlm = TileLoadMapPass::new(device, &settings);
        let tlm_bindings = tlm.bind_group(device, &height_tile_ranges(&dataset), &depth_pyramid);
        let tlm_readback = ReadbackRing::new(device, "tile load map", tlm.capacity_bytes(), DEFAULT_SLOTS);
        let terrain_bindings = terrain.bind_group(device, &heights, &imagery, ground.sampler());
        let target = |label, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: settings.render.width,
                    height: settings.render.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let colour = target("colour", COLOUR_FORMAT, usage);
        let depth = target("depth", DEPTH_FORMAT, usage);
        let seeds = match &landcover {
            Some(landcover) => {
                let depth_view = depth.create_view(&Default::default());
                let sources =
                    SeedSources { heights: &heights, landcover, imagery: &imagery, depth: &depth_view };
                seeds::SeedStage::new(&gpu, &dataset, &settings, &sources)?
            }
            None => None,
        };
        let h = &dataset.manifest.height;
        let bounds = NodeBounds::new([h.min_m, h.max_m]);
        let profiler = Profiler::new(&gpu, settings.gpu.timestamps);
        Ok(Self {
            gpu,
            dataset,
            settings,
            profiler,
            terrain,
            ground,
            heights,
            imagery,
            pinned_heights,
            pinned_imagery,
            pinned_landcover: Vec::new(),
            landcover,
            seeds,
            loader,
            depth_pyramid,
            tlm,
            tlm_bindings,
            tlm_readback,
            tlm_layouts: VecDeque::new(),
            last_tlm: None,
            last_nodes: None,
            load_maps: None,
            terrain_bindings,
            bounds,
            colour,
            depth,
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
        &self.depth
    }

    /// Renders one frame from `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<FrameReport, RenderError> {
        camera.validate()?;
        let (camera, camera_lifted_m) = self.above_ground(camera);
        let camera = &camera;
        let (width, height) = (self.settings.render.width, self.settings.render.height);
        let clip_from_view_world = camera.clip_from_view(width, height)? * camera.view_from_world();
        let frustum = Frustum::from_clip(clip_from_view_world);
        let origin = self.dataset.manifest.origin_m;
        let camera_grid_m = camera.position_m - DVec3::new(origin[0], origin[1], 0.0);
        let mut report = FrameReport { frame: self.frame, camera_lifted_m, ..Default::default() };

        // Terrain LOD: choose the nodes whose triangles keep their target size on screen.
        let lods = Lods::for_view(&self.dataset, &self.settings.terrain, camera, height);
        let selected = self.profiler.cpu("terrain_select", || {
            let (dataset, bounds) = (&self.dataset, &mut self.bounds);
            select(&lods, camera_grid_m, &frustum, &mut |node| {
                bounds.get(&lods, node, |tile| dataset.height_tile(tile).ok())
            })
        });

        // Streaming: the terrain's own height tiles first, then what the latest Tile Load Map
        // asks for; upload what arrived, within the frame's budget.
        let maps = self.load_maps.take();
        report.tlm_frame = maps.as_ref().map(|m| m.frame);
        let no_tlm_yet = LoadMaps::default();
        let latest = maps.as_ref().unwrap_or(&no_tlm_yet);
        let mut selected_heights = height_tiles(&lods, &selected);
        selected_heights.extend(
            latest.heights.iter().filter(|id| !selected_heights.contains(id)).copied().collect::<Vec<_>>(),
        );
        let wanted_heights = after_pinned(&self.pinned_heights, &selected_heights);
        let wanted_imagery = after_pinned(&self.pinned_imagery, &latest.ground);
        let wanted_landcover = after_pinned(&self.pinned_landcover, &latest.classification);
        let (frame, queue, budget) = (self.frame, &self.gpu.queue, UploadBudget::from(&self.settings.cache));
        let (heights, imagery, landcover) = (&mut self.heights, &mut self.imagery, &mut self.landcover);
        let (loader, has_imagery) = (&self.loader, self.dataset.imagery.is_some());
        let stats = self.profiler.cpu("streaming", || {
            let mut requests = heights.set_wanted(&wanted_heights, frame);
            if has_imagery {
                requests.extend(imagery.set_wanted(&wanted_imagery, frame));
            }
            if let Some(landcover) = landcover.as_mut() {
                requests.extend(landcover.set_wanted(&wanted_landcover, frame));
            }
            // Every frame, even with nothing new: it also cancels what is no longer wanted.
            loader.submit(&requests);
            let loaded = loader.try_recv_all();
            let uploads = |cache: &mut TileCache| cache.upload(queue, &loaded, budget);
            [
                uploads(heights),
                if has_imagery { uploads(imagery) } else { CacheStats::default() },
                landcover.as_mut().map(uploads).unwrap_or_default(),
            ]
        });
        [report.height, report.imagery, report.landcover] = stats;
        report.tlm_visible_cells = latest.visible_cells;
        report.tlm_patterns = latest.patterns.len();
        self.load_maps = maps;

        // This frame's Tile Load Map, over rings centred on the camera.
        let dataset_rect =
            TlmLayout::dataset_rect_m(&self.dataset.height.pyramid, self.dataset.manifest.height.spacing_m);
        let layout = TlmLayout::new(&self.settings.tlm, dataset_rect, [camera_grid_m.x, camera_grid_m.y]);
        let tlm_frame = self.tlm.prepare(
            &self.gpu.queue,
            &TlmInputs {
                settings: &self.settings.tlm,
                layout: &layout,
                camera,
                camera_grid_m,
                viewport_px: [width, height],
                lods: &lods,
                imagery: TlmImagery::of(&self.dataset, &self.settings.imagery),
                hiz_mips: self.depth_pyramid.mips(),
            },
        )?;

        // Instances: each node over its own height tile, or its finest resident ancestor.
        let (dataset, bounds) = (&self.dataset, &mut self.bounds);
        let floor_m = dataset.manifest.height.min_m;
        let (batches, dropped) =
            node_batches(&lods, &selected, camera_grid_m, &self.heights, floor_m, &mut |node| {
                bounds.get(&lods, node, |tile| dataset.height_tile(tile).ok())
            });
        report.nodes_drawn = batches.len();
        report.nodes_dropped = dropped;
        let uniforms = terrain_uniforms(
            &self.dataset,
            &self.settings,
            camera_grid_m,
            clip_from_view_world.as_mat4(),
            SKY_LINEAR,
        );
        let prepared = self.terrain.prepare(&self.gpu.queue, &uniforms, &batches);

        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let colour = self.colour.create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        // Terrain and depth: the ground every later pass stands on and is occluded by.
        self.profiler.pass(&self.gpu, &mut encoder, "terrain", |encoder| {
            self.terrain.encode(encoder, &self.terrain_bindings, &depth, &prepared)
        })?;
        // Depth pyramid: the occluders the Tile Load Map culls against, at every scale.
        self.profiler.pass(&self.gpu, &mut encoder, "depth_pyramid", |encoder| {
            self.depth_pyramid.encode(encoder, &depth)
        })?;
        // Tile Load Map: which tiles at which levels the view needs, and the seed patterns.
        self.profiler.pass(&self.gpu, &mut encoder, "tile_load_map", |encoder| {
            self.tlm.encode(encoder, &self.tlm_bindings, &tlm_frame)
        })?;
        // Ground: imagery on the surface the depth pass kept, from the finest resident level.
        let mesh = MeshDraw { terrain: &self.terrain, bind_group: &self.terrain_bindings, nodes: &prepared };
        self.last_nodes = Some(prepared.clone());
        self.profiler.pass(&self.gpu, &mut encoder, "ground", |encoder| {
            self.ground.encode(encoder, mesh, &colour, &depth, SKY_LINEAR)
        })?;
        // Seed selection: the seeds of the cells the latest TLM found near and visible.
        if let Some(stage) = self.seeds.as_mut() {
            let cells = self.load_maps.as_ref().map_or(&[][..], |m| &m.seed_cells[..]);
            let ranks = stage.tables.active_ranks();
            let inputs =
                seeds::seed_inputs(&self.settings, &self.dataset, camera, camera_grid_m, cells, ranks);
            let frame = stage.prepare(&self.gpu, &inputs)?;
            report.seed_cells = frame.cells.len();
            report.seed_cells_dropped = frame.cells_dropped;
            self.profiler.pass(&self.gpu, &mut encoder, "seed_select", |encoder| stage.encode(encoder))?;
            // Compaction: the survivors grouped per (species, LOD) into indirect draws, on the GPU.
            self.profiler
                .pass(&self.gpu, &mut encoder, "compact", |encoder| stage.encode_compact(encoder))?;
            // Drawing: one indirect draw per group, over the ground, depth-tested against it.
            stage.prepare_draw(&self.gpu, &self.settings, &uniforms);
            (report.seed_species_drawn, report.seed_species_undrawn) = stage.species_counts();
            self.profiler.pass(&self.gpu, &mut encoder, "draw_seeds", |encoder| {
                stage.encode_draw(encoder, &colour, &depth)
            })?;
        }
        // Read back a frame or two late, never waiting (recorded after the last timed pass: the
        // CPU-timing fallback submits each pass's encoder on its own).
        if self.tlm_readback.encode_copy(
            &mut encoder,
            self.tlm.output(),
            tlm_frame.output_bytes(),
            self.frame,
        ) {
            self.tlm_layouts.push_back((self.frame, layout, camera_grid_m));
        }
        if let Some(stage) = self.seeds.as_mut() {
            stage.encode_readback(&mut encoder, self.frame);
        }
        self.last_tlm = Some(tlm_frame);
        self.profiler.resolve(&mut encoder);
        self.gpu.queue.submit([encoder.finish()]);
        self.tlm_readback.submitted();
        if let Some(stage) = self.seeds.as_mut() {
            stage.submitted();
        }
        self.profiler.end_frame();
        self.gpu.device.poll(wgpu::PollType::Poll).map_err(GpuError::from)?;
        self.analyse_arrived_tlms()?;
        if let Some(stage) = self.seeds.as_mut() {
            stage.collect(&self.gpu.device)?;
            report.seeds = stage.latest;
        }
        while let Some(timings) = self.profiler.finished_frame(&self.gpu) {
            self.last_timings = timings;
        }
        self.gpu.check()?;
        self.frame += 1;
        Ok(report)
    }

    /// Turns every TLM that has arrived into load maps, keeping the newest.
    fn analyse_arrived_tlms(&mut self) -> Result<(), RenderError> {
        while let Some(readback) = self.tlm_readback.try_take(&self.gpu.device)? {
            // Layouts of skipped or older frames are dropped on the way to this one's.
            while self.tlm_layouts.front().is_some_and(|(frame, ..)| *frame < readback.frame) {
                self.tlm_layouts.pop_front();
            }
            let Some((frame, layout, camera_grid_m)) = self.tlm_layouts.pop_front() else { continue };
            let cells = readback.cast();
            let dataset = &self.dataset;
            let maps =
                self.profiler.cpu("tlm_analysis", || analyse(frame, &layout, &cells, camera_grid_m, dataset));
            self.load_maps = Some(maps);
        }
        Ok(())
    }
}
