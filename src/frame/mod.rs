//! How it works: `Renderer` owns the GPU resources of one dataset (caches, loader threads, passes,
//! targets) and `render` runs one frame in three steps: `prepare` does the frame's CPU work (the
//! terrain's LOD selection, the streaming the latest Tile Load Map asked for, every upload of the
//! frame), `encode` records the paper's passes, one line each, and the frame's readbacks are
//! recorded after them, sent, and whatever earlier readbacks have arrived is taken (`submit`).
//! Over a host's frame the same steps record into the host's encoder (`host`). Nothing in a frame
//! waits for the disk or the GPU: tiles stream in over the following frames, and until they do
//! their ancestors stand in; the Tile Load Map and pass 3's counters come back a frame or two late.

use std::sync::Arc;

use glam::DVec3;

use crate::camera::Camera;
use crate::config::Settings;
use crate::dataset::{Dataset, TileId};
use crate::earth::placing::{EarthPlacing, ExactPlacing};
use crate::gpu::counter::Counter;
use crate::gpu::counts::FrameCounts;
use crate::gpu::fragments::{CountedPass, FragmentCounter};
use crate::gpu::gpu_types::TerrainUniforms;
use crate::gpu::readback_ring::{DEFAULT_SLOTS, ReadbackRing};
use crate::gpu::{Gpu, GpuError, PassTiming, Profiler};
use crate::passes::atmosphere::gpu::AtmospherePass;
use crate::passes::depth_pyramid::gpu::DepthPyramid;
use crate::passes::display::gpu::DisplayPass;
use crate::passes::ground::gpu::GroundPass;
use crate::passes::terrain::frame::NodeBatches;
use crate::passes::terrain::gpu::{MeshDraw, PreparedNodes, TerrainPass};
use crate::passes::terrain::select::NodeBounds;
use crate::passes::tile_load_map::analysis::LoadMaps;
use crate::passes::tile_load_map::frame::{TlmEarth, TlmFrame, height_tile_ranges};
use crate::passes::tile_load_map::gpu::{TileLoadMapPass, TlmBindings};
use crate::passes::tile_load_map::layout::TlmLayout;
use crate::seeds::wind::{Wind, WindFrame};
use crate::streaming::{Delivery, Faults, Loader, LoaderOptions, TileCache};

mod clearance;
mod error;
mod host;
mod prepare;
mod query;
mod report;
mod seeds;
mod setup;
mod submit;
mod texcells;
mod tools;
mod undrawn;

pub use clearance::GROUND_CLEARANCE_NEAR;
pub use error::RenderError;
pub use host::{HostTargetError, HostTargets};
pub use query::{GroundAt, Plant, Plants};
pub use report::FrameReport;
pub use seeds::SeedReport;
pub use texcells::TexcellReport;
pub use tools::{RESOLVE_GUARD_FRAMES, Replay};
pub use undrawn::UndrawnSeeds;

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
    terrain: TerrainUniforms,
    /// The node instances drawn and the frame's f64 matrix (camera-relative metres to clip), for
    /// `drawn_ground`.
    batches: NodeBatches,
    clip_from_rel_m: glam::DMat4,
}

/// The three tile caches, with the tiles each keeps resident for good.
struct Caches {
    heights: TileCache,
    imagery: TileCache,
    /// How the loader hands the imagery cache its tiles: as stored, or decoded from blocks.
    imagery_delivery: Delivery,
    /// `None` without land cover.
    landcover: Option<TileCache>,
    /// The coarsest tiles of each layer, resident from the first frame on and never evicted (all
    /// of them after `pin_everything`; no land cover otherwise: seeds only live near the camera).
    pinned_heights: Vec<TileId>,
    pinned_imagery: Vec<TileId>,
    pinned_landcover: Vec<TileId>,
}

/// The frame's targets (the passes' light, the depth, the display made of it) and views, made once.
struct Targets {
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    display: wgpu::Texture,
    colour_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    display_view: wgpu::TextureView,
}

/// The GPU resources of one dataset (caches, loader threads, passes, targets) and the state carried
/// from frame to frame; `render` runs one frame.
pub struct Renderer {
    /// The device and queue every pass records on and submits to.
    pub gpu: Gpu,
    /// The dataset streamed, shared with the loader threads.
    pub dataset: Arc<Dataset>,
    /// The settings the renderer was made with; passes read them every frame.
    pub settings: Settings,
    /// Times every pass and the CPU steps of each frame (GPU timestamps where the adapter has them).
    pub profiler: Profiler,
    terrain: TerrainPass,
    terrain_bindings: wgpu::BindGroup,
    ground: GroundPass,
    /// The air's tables and the sky drawn from them.
    atmosphere: AtmospherePass,
    /// The frame's light exposed and through the tone curve, into the display target.
    display: DisplayPass,
    depth_pyramid: DepthPyramid,
    tlm: TileLoadMapPass,
    tlm_bindings: TlmBindings,
    tlm_readback: ReadbackRing<TlmTag>,
    /// Pass 3 and 4 and what they need; `None` without land cover.
    seeds: Option<seeds::SeedStage>,
    /// The far forest; `None` without dense classes baked, or with `texcells.reach_m` 0.
    texcells: Option<texcells::TexcellStage>,
    /// Dense classes of the dataset without a forest sample.
    texcells_unbaked: Vec<u8>,
    caches: Caches,
    loader: Loader,
    targets: Targets,
    /// Height ranges of terrain nodes, read from the packs once and kept.
    bounds: NodeBounds,
    /// Where the dataset's points are drawn: on the Earth, or flat.
    placing: EarthPlacing,
    /// The latest TLM's load maps; they drive the streaming of the next frames.
    load_maps: Option<LoadMaps>,
    last: Option<LastFrame>,
    frame: u64,
    /// The scene's time from now on, seconds (`set_time_s`): the wind's sway, the clouds' drift.
    time_s: f64,
    /// Pass timings of the most recent frame whose timings are in (a frame or two behind).
    last_timings: Vec<PassTiming>,
    /// Counts the foliage passes' fragments, with `gpu.count_fragments`.
    fragments: Option<FragmentCounter>,
    /// Counts what each pass asks of the GPU, every frame.
    counts: Counter,
    /// A frame was recorded into a host's encoder (`encode_frame`) and its readbacks have not
    /// been started: they start once the host says it submitted it, or at the next frame.
    hosted_unsubmitted: bool,
}

impl Renderer {
    /// Makes the targets, caches (pinned tiles loaded now), loader threads and passes for
    /// `dataset`; fails when the viewport, the caches or the seeds do not fit this adapter.
    pub fn new(gpu: Gpu, dataset: impl Into<Arc<Dataset>>, settings: Settings) -> Result<Self, RenderError> {
        let dataset = dataset.into();
        crate::passes::limits::check_limits(&gpu.device.limits())?;
        // A sun time that cannot be read, or one over a dataset not on the Earth, fails here.
        crate::sun::check(&settings.render, &dataset.manifest)?;
        let targets = Targets::new(&gpu.device, &settings)?;
        let device = &gpu.device;
        let terrain = TerrainPass::new(device, &settings);
        let software = gpu.info.device_type == wgpu::DeviceType::Cpu;
        let atmosphere = AtmospherePass::new(&gpu, &settings.atmosphere);
        let ground = GroundPass::new(device, &settings, software, &terrain, atmosphere.air().layout());
        let display = DisplayPass::new(&gpu, &settings.display, &targets.colour_view, atmosphere.daylight());
        let caches = Caches::new(&gpu, &dataset, &settings)?;
        let loader = Loader::new(
            Arc::clone(&dataset),
            LoaderOptions {
                threads: settings.cache.loader_threads as usize,
                delivery: caches.imagery_delivery,
                faults: Faults::new(&settings.faults),
            },
        )?;
        let depth_pyramid = DepthPyramid::new(device, settings.render.width, settings.render.height);
        let tlm = TileLoadMapPass::new(device, &settings);
        let tlm_bindings = tlm.bind_group(device, &height_tile_ranges(&dataset), &depth_pyramid);
        let tlm_readback = ReadbackRing::new(device, "tile load map", tlm.capacity_bytes(), DEFAULT_SLOTS);
        let terrain_bindings = terrain.bind_group(device, &caches.heights, &caches.imagery, ground.sampler());
        let seeds =
            seeds::SeedStage::new(&gpu, &dataset, &settings, &caches, (&targets, atmosphere.air().layout()))?;
        let (texcells, texcells_unbaked) = match &seeds {
            Some(stage) => texcells::TexcellStage::new(
                &gpu,
                &dataset,
                &settings,
                &stage.table,
                (&terrain, atmosphere.air().layout()),
                caches.landcover.as_ref(),
            )?,
            None => (None, Vec::new()),
        };
        let h = &dataset.manifest.height;
        let bounds = NodeBounds::new([h.min_m, h.max_m]);
        let m = &dataset.manifest;
        let placing = EarthPlacing::new(m.earth.as_ref(), m.origin_m, settings.render.curved_earth);
        let profiler = Profiler::new(&gpu, settings.gpu.timestamps);
        let counted = [("texcells", texcells.is_some()), ("draw_seeds", seeds.is_some())];
        let labels: Vec<_> =
            counted.into_iter().filter_map(|(label, drawn)| drawn.then_some(label)).collect();
        let fragments = match settings.gpu.count_fragments {
            true => Some(
                FragmentCounter::new(&gpu, &labels, &targets.colour).ok_or(RenderError::NoFragmentCounts)?,
            ),
            false => None,
        };
        let counts = Counter::new(&gpu, true);
        Ok(Self {
            gpu,
            dataset,
            settings,
            profiler,
            terrain,
            terrain_bindings,
            ground,
            atmosphere,
            display,
            depth_pyramid,
            tlm,
            tlm_bindings,
            tlm_readback,
            seeds,
            texcells,
            texcells_unbaked,
            caches,
            loader,
            targets,
            bounds,
            placing,
            load_maps: None,
            last: None,
            frame: 0,
            time_s: 0.0,
            last_timings: Vec::new(),
            fragments,
            counts,
            hosted_unsubmitted: false,
        })
    }

    /// Makes this renderer again with `settings`, on the same device and dataset (a new viewport,
    /// other cache sizes or seed tables): its streaming starts over from the pinned tiles, the
    /// scene's time carries on. If the new one cannot be made, this one is left as it was.
    pub fn remake(&mut self, settings: Settings) -> Result<(), RenderError> {
        let mut fresh = Self::new(self.gpu.clone(), Arc::clone(&self.dataset), settings)?;
        fresh.time_s = self.time_s;
        *self = fresh;
        Ok(())
    }

    /// The counts of every frame that has arrived since the last frame's report took them (after
    /// waiting for the GPU: all of them); never blocks.
    pub fn take_counts(&mut self) -> Result<Vec<FrameCounts>, RenderError> {
        Ok(self.counts.collect(&self.gpu.device)?)
    }

    /// Pass timings of the latest frame whose timings have arrived (never blocks for them).
    pub fn last_timings(&self) -> &[PassTiming] {
        &self.last_timings
    }

    /// Seeds pass 3 selects but pass 4 cannot draw (no `draw_seeds.impostors`, or models missing
    /// there), if any: what a command says when it starts.
    pub fn undrawn_seeds(&self) -> Option<&UndrawnSeeds> {
        self.seeds.as_ref().and_then(|s| s.undrawn.as_ref())
    }

    /// Dense land-cover classes (codes) the dataset holds whose forest sample is not in
    /// `draw_seeds.impostors`: they show bare ground beyond the seeds instead of texcells.
    pub fn texcell_classes_unbaked(&self) -> &[u8] {
        &self.texcells_unbaked
    }

    /// The terrain's reversed-Z depth of the last frame (1 near, 0 at infinity), for later passes.
    pub fn depth_texture(&self) -> &wgpu::Texture {
        &self.targets.depth
    }

    /// Sets the scene's time of the frames rendered from now on, seconds (0 at first): a flight's
    /// frame n is at `settings.wind.time_of_frame_s(n)`, so a frame number shows the same sway
    /// and the same clouds.
    pub fn set_time_s(&mut self, time_s: f64) {
        self.time_s = time_s;
    }

    /// The wind's constants for a frame from `camera` at the scene's current time.
    pub fn wind_frame(&self, camera: &Camera) -> WindFrame {
        let p = camera.position_m;
        Wind::new(&self.settings.wind).frame(self.time_s, [p.x, p.y])
    }

    /// Where this renderer draws the dataset seen from `camera` (on the Earth, or flat), exact:
    /// what turns the camera-relative positions it draws (seed records, depth) back into grid
    /// points (`ExactPlacing::grid_m`).
    pub fn exact_placing(&self, camera: &Camera) -> ExactPlacing {
        let origin = self.dataset.manifest.origin_m;
        self.placing.exact(camera.position_m - glam::DVec3::new(origin[0], origin[1], 0.0))
    }

    /// Where the Tile Load Map's cells lie seen from `camera`, as this renderer's frames place them.
    pub fn tlm_earth(&self, camera: &Camera) -> TlmEarth {
        let placing = self.exact_placing(camera);
        TlmEarth::of(&placing, &placing.nadir_node(), &self.dataset, self.settings.terrain.horizon_culling)
    }

    /// Renders one frame from `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<FrameReport, RenderError> {
        self.render_to(camera, None)
    }

    /// Renders one frame from `camera`, into its own targets or over `host`'s.
    fn render_to(
        &mut self,
        camera: &Camera,
        host: Option<&HostTargets<'_>>,
    ) -> Result<FrameReport, RenderError> {
        let (camera, mut report) = self.start_frame(camera)?;
        let frame = self.prepare(&camera, &mut report).and_then(|plan| {
            let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
            self.encode(&mut encoder, &plan.nodes, &plan.tlm, host)?;
            self.record_readbacks(&mut encoder, plan);
            self.gpu.queue.submit([encoder.finish()]);
            self.after_submit(report.frame, &mut report)
        });
        self.conclude(frame, report)
    }

    /// A frame's start: the device alive, the camera valid (and lifted above the ground), the
    /// readbacks of a frame the host recorded and has submitted since started, the counts begun.
    fn start_frame(&mut self, camera: &Camera) -> Result<(Camera, FrameReport), RenderError> {
        if let Some(why) = self.gpu.lost() {
            return Err(GpuError::DeviceLost(why).into());
        }
        camera.validate()?;
        let (camera, camera_lifted_m) = self.above_ground(camera);
        let report = FrameReport { frame: self.frame, camera_lifted_m, ..Default::default() };
        self.mark_hosted_submitted();
        self.counts.begin_frame(self.frame);
        Ok((camera, report))
    }

    /// The frame's report, or why it failed; a lost device is named as the cause.
    fn conclude(
        &self,
        frame: Result<(), RenderError>,
        report: FrameReport,
    ) -> Result<FrameReport, RenderError> {
        // A lost device fails whatever step comes next, each in its own words: say the cause.
        // wgpu tells of a loss once the queue has drained, so a frame the GPU failed waits for it.
        if matches!(frame, Err(RenderError::Gpu(_))) && self.gpu.lost().is_none() {
            let _ = self.gpu.wait();
        }
        match (frame, self.gpu.lost()) {
            (_, Some(why)) => Err(GpuError::DeviceLost(why).into()),
            (frame, None) => frame.map(|()| report),
        }
    }

    /// Records the frame's passes, in the paper's order.
    fn encode(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        nodes: &PreparedNodes,
        tlm: &TlmFrame,
        host: Option<&HostTargets<'_>>,
    ) -> Result<(), RenderError> {
        let (gpu, p, t, c) = (&self.gpu, &mut self.profiler, &self.targets, &self.counts);
        // Over a host's frame: its geometry's depth first, for every pass to meet.
        host.inspect(|h| h.copy_depth_in(encoder, &t.depth));
        // With `gpu.count_fragments`, the foliage passes count their fragments and pixels.
        let (targets, counter) = ((&t.colour_view, &t.depth_view), self.fragments.as_ref());
        let counted = |label, e: &mut _, record: &dyn Fn(&mut _, Option<CountedPass<'_>>)| {
            FragmentCounter::around(counter, label, e, &t.colour, record)
        };
        let mesh = MeshDraw { terrain: &self.terrain, bind_group: &self.terrain_bindings, nodes };
        // 0. Terrain and depth: the ground every later pass stands on and is occluded by.
        p.pass(gpu, encoder, "terrain", |e| {
            self.terrain.encode(
                e,
                &self.terrain_bindings,
                (&t.depth_view, host.is_some()),
                nodes,
                c.pass("terrain"),
            )
        })?;
        // The depth pyramid: the occluders the Tile Load Map culls against, at every scale.
        p.pass(gpu, encoder, "depth_pyramid", |e| {
            self.depth_pyramid.encode(e, &t.depth_view, c.pass("depth_pyramid"))
        })?;
        // 1. Tile Load Map: which tiles at which levels the view needs, and the seed patterns.
        p.pass(gpu, encoder, "tile_load_map", |e| {
            self.tlm.encode(e, &self.tlm_bindings, tlm, c.pass("tile_load_map"))
        })?;
        // The air: the sky seen from the camera's altitude, and what lies between the camera and
        // everything drawn next (lit and seen through it, `shared/air.wgsl`).
        p.pass(gpu, encoder, "sky_view", |e| self.atmosphere.encode_sky_view(e, c.pass("sky_view")))?;
        p.pass(gpu, encoder, "aerial_perspective", |e| {
            self.atmosphere.encode_aerial(e, c.pass("aerial_perspective"))
        })?;
        let air = self.atmosphere.air();
        // 2. Ground: imagery on the surface the depth pass kept, from the finest resident level.
        p.pass(gpu, encoder, "ground", |e| self.ground.encode(e, mesh, targets, air, c.pass("ground")))?;
        // The sky, drawn where nothing was.
        p.pass(gpu, encoder, "sky", |e| self.atmosphere.encode_sky(e, targets, c.pass("sky")))?;
        if let Some(stage) = &self.texcells {
            // The far forest: slices of the dense classes' samples over the ground beyond the seeds.
            let counting = c.pass("texcells");
            let draw = |e: &mut _, count: Option<CountedPass<'_>>| {
                stage.encode(e, (mesh, air), targets, (count, counting))
            };
            p.pass(gpu, encoder, "texcells", |e| counted("texcells", e, &draw))?;
        }
        if let Some(stage) = &self.seeds {
            // 3. Seed selection: the seeds of the cells the latest TLM found near and visible.
            p.pass(gpu, encoder, "seed_select", |e| stage.encode(e, c.pass("seed_select")))?;
            // 4a. Compaction: the survivors grouped per (species, LOD) into indirect draws, on the GPU.
            p.pass(gpu, encoder, "compact", |e| stage.encode_compact(e, c.pass("compact")))?;
            // 4b. Drawing: one indirect draw per group, over the ground, depth-tested against it.
            let counting = c.pass("draw_seeds");
            let draw = |e: &mut _, count: Option<CountedPass<'_>>| {
                stage.encode_draw(e, (targets, air), (count, counting))
            };
            p.pass(gpu, encoder, "draw_seeds", |e| counted("draw_seeds", e, &draw))?;
        }
        // The frame's light as the screen shows it: exposed, through the tone curve.
        p.pass(gpu, encoder, "display", |e| match host {
            Some(h) => self.display.encode_over(e, &h.colour_view(), c.pass("display")),
            None => self.display.encode(e, &t.display_view, c.pass("display")),
        })?;
        // The terrain's and the trees' depth back to the host, for what it draws next.
        host.inspect(|h| h.copy_depth_back(encoder, &t.depth));
        Ok(())
    }
}
