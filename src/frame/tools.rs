//! How it works: what tools and tests ask of a renderer besides frames: all-resident references,
//! rendering a view until it has streamed in, and blocking readbacks of the targets, the seeds and
//! their compaction, with the CPU twins to compare them with. None of it is on the per-frame path.

use std::time::Duration;

use crate::camera::Camera;
use crate::classes::ClassTable;
use crate::gpu::GpuError;
use crate::gpu::counter::Counting;
use crate::gpu::gpu_types::{SeedCounters, SeedDrawArgs, SeedRecord, TerrainUniforms, TlmCell};
use crate::gpu::readback::{f16_texels, read_texture, read_values};
use crate::light::CloudShadowFrame;
use crate::passes::compact::frame::Compacted;
use crate::passes::seed_select::frame::{SeedCellRef, SeedOutput};
use crate::passes::seed_select::march::BLOCKS_PER_TILE;
use crate::reference::oracle::OracleInputs;
use crate::reference::seed_select::{SeedSnapshot, seed_select, seed_select_blocks, snapshot_caches};
use crate::seeds::SeedTables;
use crate::seeds::patterns::SeedPatterns;
use crate::streaming::loader::imagery_tile;
use crate::streaming::wants::pinned_tiles;
use crate::streaming::{CacheStats, TileCache};

use super::{FrameReport, RenderError, Renderer};

/// A settled frame's targets, to draw more over (`Renderer::last_canvas`).
pub(crate) struct Canvas<'a> {
    pub terrain: &'a TerrainUniforms,
    pub colour: &'a wgpu::Texture,
    pub depth: &'a wgpu::Texture,
    /// The air the frame was lit and seen through (its tables hold the last frame's view).
    pub air: &'a crate::passes::atmosphere::gpu::air::Air,
}

/// Frames `Renderer::render_resolved` renders at most before it calls a view stuck: far more than
/// any view needs (every frame uploads a tile or waits for the loaders to read one), so only a hang
/// reaches it.
pub const RESOLVE_GUARD_FRAMES: u32 = 100_000;

/// How long `render_resolved` waits for the loaders between two frames, at most: a guard against a
/// hung reader (the wait ends as soon as a tile is read or nothing is left to read).
const LOADER_WAIT: Duration = Duration::from_secs(30);

impl Renderer {
    /// Loads every tile of the dataset now (heights, imagery, land cover) and pins it, for
    /// all-resident reference renders. Fails when a layer does not fit its cache.
    pub fn pin_everything(&mut self) -> Result<(), RenderError> {
        let everything = |cache: &TileCache, layer: &'static str| {
            let pyramid = cache.pyramid();
            if pyramid.tile_count() > cache.capacity() as u64 {
                return Err(RenderError::DoesNotFit {
                    layer,
                    tiles: pyramid.tile_count(),
                    slots: cache.capacity(),
                });
            }
            Ok(pinned_tiles(pyramid, usize::MAX))
        };
        let (queue, c, frame) = (&self.gpu.queue, &mut self.caches, self.frame);
        c.pinned_heights = everything(&c.heights, "height")?;
        c.heights.load_now(queue, &c.pinned_heights, frame, |id| self.dataset.height.tile_bytes(id));
        if let Some(layer) = &self.dataset.imagery {
            c.pinned_imagery = everything(&c.imagery, "imagery")?;
            let delivery = c.imagery_delivery;
            c.imagery.load_now(queue, &c.pinned_imagery, frame, |id| imagery_tile(layer, id, delivery));
        }
        if let (Some(layer), Some(cache)) = (&self.dataset.landcover, c.landcover.as_mut()) {
            c.pinned_landcover = everything(cache, "land-cover")?;
            cache.load_now(queue, &c.pinned_landcover, frame, |id| layer.tile_bytes(id));
        }
        Ok(())
    }

    /// Whether every tile the frame of `report` wanted is resident (or failed, or beyond what the
    /// cache can hold), with nothing left loading or waiting for upload.
    pub fn is_resolved(&self, report: &FrameReport) -> bool {
        let done = |s: &CacheStats, cache: &TileCache| {
            s.needed_resident + s.failed >= s.needed.min(cache.capacity()) && s.staged == 0
        };
        let c = &self.caches;
        let landcover = match &c.landcover {
            Some(cache) => done(&report.landcover, cache),
            None => true,
        };
        done(&report.height, &c.heights)
            && done(&report.imagery, &c.imagery)
            && landcover
            && self.loader.is_idle()
    }

    /// Renders `camera` frame after frame until everything it needs is resident, for single
    /// frames and references. Between frames it waits for the GPU (so the frame's Tile Load Map
    /// arrives in the next) and for the loaders to deliver something new, so the view resolves by
    /// state in the same frames on a fast or a loaded machine. Returns the last frame's report and
    /// the number of frames it took; `RenderError::Unresolved` if `RESOLVE_GUARD_FRAMES` pass first
    /// (something is stuck).
    pub fn render_resolved(&mut self, camera: &Camera) -> Result<(FrameReport, u32), RenderError> {
        let first = self.frame;
        for frames in 1..=RESOLVE_GUARD_FRAMES {
            let report = self.render(camera)?;
            // Resolved only once a Tile Load Map of this very view has driven the streaming.
            let informed = report.tlm_frame.is_some_and(|f| f >= first);
            if informed && self.is_resolved(&report) {
                return Ok((report, frames));
            }
            self.gpu.wait()?;
            self.loader.wait_for_progress(LOADER_WAIT);
        }
        Err(RenderError::Unresolved { frames: RESOLVE_GUARD_FRAMES })
    }

    /// The imagery cache: its texture format (the dataset's blocks, or RGBA8) and slots.
    pub fn imagery_cache(&self) -> &TileCache {
        &self.caches.imagery
    }

    /// Every tile cache: heights, imagery, then land cover when the dataset has it.
    pub fn tile_caches(&self) -> Vec<&TileCache> {
        let c = &self.caches;
        [&c.heights, &c.imagery].into_iter().chain(c.landcover.as_ref()).collect()
    }

    /// The last frame as the screen shows it, an sRGB image: its light through the display pass,
    /// displayed again now so that whatever was drawn over the frame since (the ground truth's
    /// seeds) is in it.
    pub fn read_colour(&self) -> Result<image::RgbaImage, RenderError> {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.display.encode(&mut encoder, &self.targets.display_view, Counting::OFF);
        self.gpu.queue.submit([encoder.finish()]);
        self.read_display(&self.targets.display)
    }

    /// `light` (a texture of the colour target's format, drawn over a copy of the frame) as this
    /// renderer's display shows it, an sRGB image.
    pub(crate) fn display_light(&self, light: &wgpu::Texture) -> Result<image::RgbaImage, RenderError> {
        let device = &self.gpu.device;
        let display = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("displayed light"),
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            format: crate::passes::DISPLAY_FORMAT,
            view_formats: &[],
            size: light.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        let (light, view) =
            (light.create_view(&Default::default()), display.create_view(&Default::default()));
        self.display.encode_light(device, &mut encoder, &light, &view);
        self.gpu.queue.submit([encoder.finish()]);
        self.read_display(&display)
    }

    fn read_display(&self, display: &wgpu::Texture) -> Result<image::RgbaImage, RenderError> {
        let bytes = read_texture(&self.gpu, display, wgpu::TextureAspect::All, 4)?;
        image::RgbaImage::from_raw(display.width(), display.height(), bytes)
            .ok_or_else(|| RenderError::Gpu(GpuError::Validation("readback size mismatch".into())))
    }

    /// The last frame's light before the display exposes it: linear RGB balanced for daylight
    /// (1 is white ground in daylight; `passes::display`), row by row, top row first.
    pub fn read_light(&self) -> Result<Vec<[f32; 3]>, RenderError> {
        let bytes = read_texture(&self.gpu, &self.targets.colour, wgpu::TextureAspect::All, 8)?;
        Ok(f16_texels(&bytes).into_iter().map(|[r, g, b, _]| [r, g, b]).collect())
    }

    /// A view of the last frame's display as plain `Rgba8Unorm` (the sRGB-encoded bytes, not
    /// decoded when sampled): what a window shows them through, byte for byte.
    pub fn display_bytes_view(&self) -> wgpu::TextureView {
        self.targets.display.create_view(&wgpu::TextureViewDescriptor {
            format: Some(crate::passes::DISPLAY_FORMAT.remove_srgb_suffix()),
            ..Default::default()
        })
    }

    /// The last frame's depth (reversed-Z: 1 at the near plane, 0 for the sky), top row first.
    pub fn read_depth(&self) -> Result<Vec<f32>, RenderError> {
        let bytes = read_texture(&self.gpu, &self.targets.depth, wgpu::TextureAspect::DepthOnly, 4)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// The last frame's Tile Load Map as pass 1 wrote it, waiting for the GPU (`None` before a
    /// first frame): one cell per ring cell, ring by ring (`TlmLayout::cell_of`).
    pub fn read_tile_load_map(&self) -> Result<Option<Vec<TlmCell>>, RenderError> {
        let Some(last) = &self.last else { return Ok(None) };
        Ok(Some(self.tlm.read_back(&self.gpu, &last.tlm)?))
    }

    /// The seeded world of this renderer: species tables and patterns (`None` without land cover).
    pub fn seed_world(&self) -> Option<(&SeedTables, &SeedPatterns)> {
        self.seeds.as_ref().map(|s| (&s.tables, &s.patterns))
    }

    /// What the exact oracle reads to judge this renderer's view from `camera`: its dataset,
    /// settings and seeded world (`None` without land cover).
    pub fn oracle_inputs<'a>(&'a self, camera: &'a Camera) -> Option<OracleInputs<'a>> {
        let (tables, patterns) = self.seed_world()?;
        Some(OracleInputs {
            dataset: &self.dataset,
            settings: &self.settings,
            tables,
            patterns,
            camera,
            viewport_px: [self.settings.render.width, self.settings.render.height],
        })
    }

    /// The cloud shadows the last frame was lit with (`None` before a first frame).
    pub fn last_clouds(&self) -> Option<CloudShadowFrame> {
        let terrain = &self.last.as_ref()?.terrain;
        Some(CloudShadowFrame { field: terrain.cloud_field, shift: terrain.cloud_shift })
    }

    /// The class table the species come from (`None` without land cover).
    pub fn class_table(&self) -> Option<&ClassTable> {
        self.seeds.as_ref().map(|s| &s.table)
    }

    /// What the ground truth draws its seeds over: the last frame's terrain uniforms (matrix,
    /// sun) and its colour and depth targets (`None` before a first frame).
    pub(crate) fn last_canvas(&self) -> Option<Canvas<'_>> {
        let last = self.last.as_ref()?;
        Some(Canvas {
            terrain: &last.terrain,
            colour: &self.targets.colour,
            depth: &self.targets.depth,
            air: self.atmosphere.air(),
        })
    }

    /// The last frame's seeds as pass 3 wrote them, with its counters, waiting for the GPU
    /// (`None` without land cover). Records come in no particular order.
    pub fn read_seeds(&self) -> Result<Option<(Vec<SeedRecord>, SeedCounters)>, RenderError> {
        let Some(stage) = &self.seeds else { return Ok(None) };
        Ok(Some(stage.pass.read_back(&self.gpu)?))
    }

    /// Everything pass 3 wrote in the last frame (records, keys, block table, counters), waiting
    /// for the GPU (`None` without land cover or before a first frame).
    pub fn read_seed_output(&self) -> Result<Option<SeedOutput>, RenderError> {
        let Some(stage) = &self.seeds else { return Ok(None) };
        let Some(frame) = &stage.last_frame else { return Ok(None) };
        Ok(Some(stage.pass.read_output(&self.gpu, frame)?))
    }

    /// The last frame's compaction (draw order over pass 3's records, indirect draws), waiting for
    /// the GPU (`None` without land cover).
    pub fn read_compacted(&self) -> Result<Option<Compacted>, RenderError> {
        let Some(stage) = &self.seeds else { return Ok(None) };
        Ok(Some(stage.compact.read_back(&self.gpu)?))
    }

    /// The block tops the height cache keeps beside its slots (`march::BLOCK_TOPS`), as the GPU
    /// holds them: `BLOCKS_PER_TILE` per slot, slot by slot.
    pub fn height_block_tops(&self) -> Result<Vec<f32>, RenderError> {
        let heights = &self.caches.heights;
        let Some(buffer) = heights.summary_buffer() else { return Ok(Vec::new()) };
        let count = u64::from(heights.slot_count()) * BLOCKS_PER_TILE as u64;
        Ok(read_values(&self.gpu, buffer, count)?)
    }

    /// What pass 3 read in the last frame (its cells, the resident tiles, the depth), for its
    /// twin; `None` without land cover or before a first frame.
    pub fn seed_snapshot(&self) -> Result<Option<SeedSnapshot>, RenderError> {
        let c = &self.caches;
        let (Some(stage), Some(landcover)) = (&self.seeds, &c.landcover) else { return Ok(None) };
        let Some(frame) = &stage.last_frame else { return Ok(None) };
        let caches = snapshot_caches(&self.dataset, &c.heights, landcover, &c.imagery)?;
        Ok(Some(SeedSnapshot {
            frame: frame.clone(),
            patterns_unit: stage.patterns.positions_unit.clone(),
            tables: stage.tables.clone(),
            caches,
            depth: self.terrain_depth()?,
        }))
    }

    /// The last frame's terrain depth alone (reversed-Z, top row first): what pass 3 culled
    /// against, before pass 4 drew the trees into the depth target. The terrain pass is recorded
    /// again over the last frame's instances into a scratch target (the renderer's own are left
    /// as they are), and read back, waiting for the GPU. Before a first frame, the depth target.
    pub fn terrain_depth(&self) -> Result<Vec<f32>, RenderError> {
        let Some(last) = &self.last else { return self.read_depth() };
        let depth = &self.targets.depth;
        let scratch = self.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("terrain depth, for the twins"),
            size: depth.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: depth.format(),
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let view = scratch.create_view(&Default::default());
        self.terrain.encode(&mut encoder, &self.terrain_bindings, (&view, false), &last.nodes, Counting::OFF);
        self.gpu.queue.submit([encoder.finish()]);
        let bytes = read_texture(&self.gpu, &scratch, wgpu::TextureAspect::DepthOnly, 4)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Pass 3 replayed by its CPU twin over the last frame's inputs, in canonical order.
    pub fn seed_twin(&self) -> Result<Option<(Vec<SeedRecord>, SeedCounters)>, RenderError> {
        Ok(self.seed_snapshot()?.map(|snapshot| seed_select(&snapshot.inputs())))
    }

    /// Pass 3 and compaction replayed by their CPU twins over the last frame's inputs: pass 3's
    /// output with its blocks in table order, and its compaction (`None` without land cover).
    pub fn compact_twin(&self) -> Result<Option<(SeedOutput, Compacted)>, RenderError> {
        let (Some(stage), Some(snapshot)) = (&self.seeds, self.seed_snapshot()?) else { return Ok(None) };
        let output = seed_select_blocks(&snapshot.inputs());
        let templates = stage.compact.templates();
        let compacted = crate::reference::compact::compact(&output.keys, &output.blocks, templates)?;
        Ok(Some((output, compacted)))
    }

    /// The index ranges compaction fills the draws from (`SEED_DRAWS`), as the last frame set them
    /// (continuous LOD narrows them per frame); `None` without land cover.
    pub fn seed_draw_templates(&self) -> Option<Vec<SeedDrawArgs>> {
        self.seeds.as_ref().map(|stage| stage.compact.templates().to_vec())
    }

    /// Runs pass 3 alone over `cells` seen from `camera`, against the caches and depth as the last
    /// frame left them, and waits for it: for benchmarks, which choose how many seeds to check.
    /// `read_seeds` then reads its output.
    pub fn run_seed_select(&mut self, camera: &Camera, cells: &[SeedCellRef]) -> Result<(), RenderError> {
        let exact = self.exact_placing(camera);
        let Some(stage) = self.seeds.as_mut() else { return Ok(()) };
        let cells =
            super::seeds::placed_cells(&mut self.placing.view(&exact), cells, self.settings.tlm.cell_m);
        let ranks = stage.tables.active_ranks();
        let (settings, dataset) = (&self.settings, &self.dataset);
        let nadir = exact.nadir_node();
        let inputs = super::seeds::seed_inputs(settings, dataset, camera, &exact, nadir, &cells, ranks);
        // Its uploads go to a tally the next frame starts afresh.
        stage.prepare(&self.gpu, &inputs, &self.counts)?;
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        stage.encode(&mut encoder, Counting::OFF);
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.wait()?;
        self.gpu.check()?;
        Ok(())
    }

    /// Replays the last frame's terrain depth and then its seed passes up to `through` (pass 3
    /// over its cells and compaction; then the draw into the colour and depth), as that frame
    /// recorded them, and waits for the GPU: for benchmarks of a fixed camera. The depth comes
    /// first because pass 3 must see the terrain's alone, not the trees the last draw left in
    /// it. `false` when the last frame ran no seed passes.
    pub fn replay_seed_passes(&mut self, through: Replay) -> Result<bool, RenderError> {
        let (Some(stage), Some(last)) = (self.seeds.as_ref(), self.last.as_ref()) else {
            return Ok(false);
        };
        if stage.last_frame.is_none() {
            return Ok(false);
        }
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let t = &self.targets;
        self.terrain.encode(
            &mut encoder,
            &self.terrain_bindings,
            (&t.depth_view, false),
            &last.nodes,
            Counting::OFF,
        );
        if through != Replay::Depth {
            stage.encode(&mut encoder, Counting::OFF);
            stage.encode_compact(&mut encoder, Counting::OFF);
        }
        if through == Replay::Draw {
            let targets = ((&t.colour_view, &t.depth_view), self.atmosphere.air());
            stage.encode_draw(&mut encoder, targets, (None, Counting::OFF));
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.wait()?;
        self.gpu.check()?;
        Ok(true)
    }
}

/// How far `Renderer::replay_seed_passes` goes after the terrain's depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Replay {
    /// The terrain's depth only.
    Depth,
    /// Pass 3 and compaction.
    Select,
    /// Pass 3, compaction and the draw.
    Draw,
}
