//! How it works: the CPU half of a frame, done before anything is recorded. The terrain's LOD
//! selection picks the nodes; the streaming hands each cache what the terrain and the latest Tile
//! Load Map want and uploads what the loader read, within the frame's budget; then every upload
//! of the frame is written: the TLM's rings, the terrain's instances and uniforms, pass 3's cells
//! and pass 4's constants, each step's bytes counted as its pass's (the caches' as `streaming`).
//! `encode` then only records commands over what this left.

use glam::{DMat4, DVec3};

use crate::camera::{Camera, Frustum};
use crate::earth::horizon::fall_per_m2;
use crate::earth::placing::ExactPlacing;
use crate::gpu::gpu_types::{EarthNode, TerrainUniforms};
use crate::passes::atmosphere::frame::SkyView;
use crate::passes::terrain::frame::{FrameLight, NodeBatches, height_tiles, node_batches, terrain_uniforms};
use crate::passes::terrain::gpu::PreparedNodes;
use crate::passes::terrain::select::{Lods, Selected, select};
use crate::passes::tile_load_map::analysis::LoadMaps;
use crate::passes::tile_load_map::frame::{TlmEarth, TlmFrame, TlmImagery, TlmInputs};
use crate::passes::tile_load_map::layout::TlmLayout;
use crate::streaming::wants::after_pinned;
use crate::streaming::{CacheStats, TileCache, UploadBudget};
use crate::sun::frame_sun_dir;

use super::texcells::TexcellView;
use super::{FrameReport, RenderError, Renderer};

/// What `prepare` uploaded for a frame, which the passes are recorded over.
pub(super) struct FramePlan {
    /// The frame's TLM rings, and where the camera was (the TLM's readback is read against them).
    pub layout: TlmLayout,
    pub camera_grid_m: DVec3,
    pub tlm: TlmFrame,
    pub nodes: PreparedNodes,
    /// The terrain's uniforms: its matrix, sun and clouds, which everything drawn over it shares.
    pub terrain: TerrainUniforms,
    /// The node instances drawn, kept for the CPU's rebuild of the drawn ground, and the f64
    /// matrix they were drawn with (camera-relative metres to clip).
    pub batches: NodeBatches,
    pub clip_from_rel_m: DMat4,
}

/// The camera, as this frame's passes see it.
struct View<'a> {
    camera: &'a Camera,
    /// Camera position in grid space (CRS position − `Manifest::origin_m`), metres.
    grid_m: DVec3,
    clip_from_view_world: glam::DMat4,
    lods: Lods,
    /// Where this frame draws the dataset (on the Earth, or flat), from this camera.
    placing: ExactPlacing,
    /// The mapping of the grid point under the camera (`ExactPlacing::nadir_node`): how the
    /// TLM's boxes bend and where the seeds stand up.
    nadir: EarthNode,
    /// Towards the sun, in the camera-relative world (`sun::frame_sun_dir`).
    sun_dir: DVec3,
}

impl Renderer {
    /// The frame's CPU work and uploads, for `camera` (already above the ground).
    pub(super) fn prepare(
        &mut self,
        camera: &Camera,
        report: &mut FrameReport,
    ) -> Result<FramePlan, RenderError> {
        let (width, height) = (self.settings.render.width, self.settings.render.height);
        let origin = self.dataset.manifest.origin_m;
        let grid_m = camera.position_m - DVec3::new(origin[0], origin[1], 0.0);
        let placing = self.placing.exact(grid_m);
        let view = View {
            camera,
            grid_m,
            clip_from_view_world: camera.clip_from_view(width, height)? * camera.view_from_world(),
            lods: Lods::for_view(&self.dataset, &self.settings.terrain, camera, height),
            nadir: placing.nadir_node(),
            placing,
            sun_dir: frame_sun_dir(
                &self.settings.render,
                self.dataset.manifest.earth.as_ref(),
                camera.position_m,
            )?,
        };
        let selected = self.select_nodes(&view);
        self.stream(&view, &selected, report);
        let (layout, tlm) = self.prepare_tlm(&view)?;
        let (nodes, terrain, batches) = self.prepare_terrain(&view, &selected, report);
        self.prepare_seeds(&view, &terrain, report)?;
        let clip_from_rel_m = view.clip_from_view_world;
        Ok(FramePlan { layout, camera_grid_m: view.grid_m, tlm, nodes, terrain, batches, clip_from_rel_m })
    }

    /// Terrain LOD: the nodes whose triangles keep their target size on screen.
    fn select_nodes(&mut self, view: &View) -> Vec<Selected> {
        let frustum = Frustum::from_clip(view.clip_from_view_world);
        let (dataset, bounds) = (&self.dataset, &mut self.bounds);
        let mut placed = self.placing.view(&view.placing);
        let horizon =
            self.settings.terrain.horizon_culling.then_some(f64::from(dataset.manifest.height.min_m));
        self.profiler.cpu("terrain_select", || {
            select(&view.lods, &mut placed, &frustum, horizon, &mut |node| {
                bounds.get(&view.lods, node, |tile| dataset.height_tile(tile).ok())
            })
        })
    }

    /// Streaming: the terrain's own height tiles first, then what the latest Tile Load Map asks
    /// for; upload what arrived, within the frame's budget.
    fn stream(&mut self, view: &View, selected: &[Selected], report: &mut FrameReport) {
        let no_tlm_yet = LoadMaps::default();
        let latest = self.load_maps.as_ref().unwrap_or(&no_tlm_yet);
        report.tlm_frame = self.load_maps.as_ref().map(|m| m.frame);
        report.tlm_visible_cells = latest.visible_cells;
        report.tlm_patterns = latest.patterns.len();
        let mut selected_heights = height_tiles(&view.lods, selected);
        let prefetch: Vec<_> =
            latest.heights.iter().filter(|id| !selected_heights.contains(id)).copied().collect();
        selected_heights.extend(prefetch);
        let c = &mut self.caches;
        let wanted_heights = after_pinned(&c.pinned_heights, &selected_heights);
        let wanted_imagery = after_pinned(&c.pinned_imagery, &latest.ground);
        let mut classification = latest.classification.clone();
        if let Some(stage) = &self.texcells {
            let far: Vec<_> =
                stage.wanted_landcover.iter().filter(|id| !classification.contains(id)).copied().collect();
            classification.extend(far);
        }
        let wanted_landcover = after_pinned(&c.pinned_landcover, &classification);
        let (frame, queue, budget) = (self.frame, &self.gpu.queue, UploadBudget::from(&self.settings.cache));
        let uploaded_before = queue.uploaded_bytes();
        let (loader, has_imagery) = (&self.loader, self.dataset.imagery.is_some());
        let (heights, imagery, landcover) = (&mut c.heights, &mut c.imagery, &mut c.landcover);
        [report.height, report.imagery, report.landcover] = self.profiler.cpu("streaming", || {
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
        self.counts.uploaded("streaming", queue.uploaded_bytes() - uploaded_before);
    }

    /// This frame's Tile Load Map, over rings centred on the camera.
    fn prepare_tlm(&self, view: &View) -> Result<(TlmLayout, TlmFrame), RenderError> {
        let s = &self.settings;
        let dataset_rect =
            TlmLayout::dataset_rect_m(&self.dataset.height.pyramid, self.dataset.manifest.height.spacing_m);
        let layout = TlmLayout::new(&s.tlm, dataset_rect, [view.grid_m.x, view.grid_m.y]);
        let inputs = TlmInputs {
            settings: &s.tlm,
            layout: &layout,
            camera: view.camera,
            camera_grid_m: view.grid_m,
            viewport_px: [s.render.width, s.render.height],
            lods: &view.lods,
            imagery: TlmImagery::of(&self.dataset, &s.imagery),
            hiz_mips: self.depth_pyramid.mips(),
            earth: TlmEarth::of(&view.placing, &view.nadir, &self.dataset, s.terrain.horizon_culling),
        };
        let queue = &self.gpu.queue;
        let tlm = self.counts.uploads(queue, "tile_load_map", || self.tlm.prepare(queue, &inputs))?;
        Ok((layout, tlm))
    }

    /// The terrain's instances (each node over its own height tile, or its finest resident
    /// ancestor) and the uniforms both terrain passes read, uploaded; the uniforms are returned
    /// for pass 4, which draws with the same matrix, sun and clouds.
    fn prepare_terrain(
        &mut self,
        view: &View,
        selected: &[Selected],
        report: &mut FrameReport,
    ) -> (PreparedNodes, TerrainUniforms, NodeBatches) {
        let (dataset, bounds) = (&self.dataset, &mut self.bounds);
        let floor_m = dataset.manifest.height.min_m;
        let mut placed = self.placing.view(&view.placing);
        let (batches, dropped) =
            node_batches(&view.lods, selected, &mut placed, &self.caches.heights, floor_m, &mut |node| {
                bounds.get(&view.lods, node, |tile| dataset.height_tile(tile).ok())
            });
        report.nodes_drawn = batches.len();
        report.nodes_dropped = dropped;
        let clip = view.clip_from_view_world.as_mat4();
        let fall = fall_per_m2(&view.nadir);
        let light = FrameLight { sun_dir: view.sun_dir };
        let uniforms =
            terrain_uniforms(&self.dataset, &self.settings, view.grid_m, clip, light, self.time_s, fall);
        let (queue, counts) = (&self.gpu.queue, &self.counts);
        let nodes = counts.uploads(queue, "terrain", || self.terrain.prepare(queue, &uniforms, &batches));
        // The camera's frame is its own local one, on the Earth or flat: its zenith is +z.
        let sky = SkyView {
            view_world_from_clip: view.clip_from_view_world.inverse(),
            up: DVec3::Z,
            sun_dir: view.sun_dir,
            altitude_m: view.grid_m.z,
        };
        let live = &self.settings.atmosphere;
        counts.uploads(queue, "sky_view", || self.atmosphere.prepare(queue, &sky, live));
        counts.uploads(queue, "display", || self.display.prepare(queue, &self.settings.display));
        if let Some(stage) = self.texcells.as_mut() {
            let texcell_view = TexcellView {
                camera_grid_m: view.grid_m,
                metres_per_px_at_1m: view.camera.metres_per_pixel(1.0, self.settings.render.height),
            };
            report.texcells = self.profiler.cpu("texcell_place", || {
                counts.uploads(queue, "texcells", || {
                    stage.prepare(&self.gpu, &self.settings, &self.dataset, &batches, &nodes, &texcell_view)
                })
            });
        }
        (nodes, uniforms, batches)
    }

    /// Pass 3's cells (those the latest TLM found near and visible), and pass 4's constants (the
    /// terrain's matrix, sun and clouds).
    fn prepare_seeds(
        &mut self,
        view: &View,
        terrain: &TerrainUniforms,
        report: &mut FrameReport,
    ) -> Result<(), RenderError> {
        let wind = self.wind_frame(view.camera);
        let Some(stage) = self.seeds.as_mut() else { return Ok(()) };
        let cells = self.load_maps.as_ref().map_or(&[][..], |m| &m.seed_cells[..]);
        let mut placed = self.placing.view(&view.placing);
        let cells = super::seeds::placed_cells(&mut placed, cells, self.settings.tlm.cell_m);
        let ranks = stage.tables.active_ranks();
        let (settings, dataset) = (&self.settings, &self.dataset);
        let inputs = super::seeds::seed_inputs(
            settings,
            dataset,
            view.camera,
            &view.placing,
            view.nadir,
            &cells,
            ranks,
        );
        let frame = stage.prepare(&self.gpu, &inputs, &self.counts)?;
        report.seed_cells = frame.cells.len();
        report.seed_cells_dropped = frame.cells_dropped;
        stage.prepare_draw(&self.gpu, &self.settings, terrain, (&wind, &inputs.nadir), &self.counts);
        (report.seed_species_drawn, report.seed_species_undrawn) = stage.species_counts();
        Ok(())
    }
}
