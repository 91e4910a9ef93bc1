//! How it works: the renderer's seed stage. A dataset with land cover gets, once, its species
//! tables (from the class table its scheme names, or `seeds.class_table`), the P generic patterns
//! and pass 3's pipeline bound to the caches and the depth target, and compaction bound to pass 3's
//! block table and keys. Each frame it feeds pass 3 the ring-0 cells of the latest Tile Load Map,
//! has compaction group the survivors into one indirect draw per (species, LOD) on the GPU, and
//! reads only pass 3's counters back, through a staging ring, never waiting: the counters a frame
//! reports are a frame or two old. With `draw_seeds.impostors` set, it also loads each species'
//! impostor once, gives compaction the draw pass's templates, and has pass 4 draw the groups.

use std::path::Path;

use glam::DVec3;

use crate::camera::Camera;
use crate::classes::ClassTable;
use crate::config::Settings;
use crate::dataset::{Dataset, LandcoverLayer};
use crate::earth::placing::{ExactPlacing, PlacedView};
use crate::gpu::counter::{Counter, Counting};
use crate::gpu::fragments::CountedPass;
use crate::gpu::gpu_types::{CompactParams, EarthNode, SeedCounters, SeedRecord, TerrainUniforms};
use crate::gpu::readback_ring::{DEFAULT_SLOTS, ReadbackRing};
use crate::gpu::{Gpu, GpuError};
use crate::passes::compact::frame::CompactLimits;
use crate::passes::compact::gpu::{CompactInputs, CompactPass};
use crate::passes::draw_seeds::LodChoices;
use crate::passes::draw_seeds::frame::{draw_uniforms, load_impostors};
use crate::passes::draw_seeds::gpu::{DrawSeedsInputs, DrawSeedsPass};
use crate::passes::seed_select::frame::{SeedCellRef, SeedFrame, SeedInputs};
use crate::passes::seed_select::gpu::{SeedSelectPass, SeedSources};
use crate::passes::seed_select::march::height_tile_max_m;
use crate::seeds::SeedTables;
use crate::seeds::patterns::SeedPatterns;
use crate::seeds::wind::WindFrame;
use crate::streaming::TileCache;

use super::{Caches, RenderError, Targets, UndrawnSeeds};

/// Pass 3's counters for one frame, as the frame log records them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SeedReport {
    /// The frame these counters are from.
    pub frame: u64,
    /// Cells checked (`checked = cells × ranks`).
    pub cells: u32,
    /// Ranks checked in each cell: the first seeds of its pattern, those some class can grow.
    pub ranks: u32,
    /// What pass 3 counted: seeds selected, overflowed, checked, and culled by each test.
    #[serde(flatten)]
    pub counters: SeedCounters,
}

/// What a frame's counters are read with: the frame, its cells and the ranks checked in each.
#[derive(Debug, Clone, Copy)]
struct CountersTag {
    frame: u64,
    cells: u32,
    ranks: u32,
}

pub(super) struct SeedStage {
    /// The class table the species come from.
    pub table: ClassTable,
    pub tables: SeedTables,
    pub patterns: SeedPatterns,
    pub pass: SeedSelectPass,
    pub bind_group: wgpu::BindGroup,
    pub compact: CompactPass,
    compact_bind_group: wgpu::BindGroup,
    /// Pass 4 and its bindings; `None` without `draw_seeds.impostors`.
    draw: Option<(DrawSeedsPass, wgpu::BindGroup)>,
    /// The last frame's compaction size.
    compact_params: CompactParams,
    counters_ring: ReadbackRing<CountersTag>,
    /// The last frame's inputs, for the twin.
    pub last_frame: Option<SeedFrame>,
    pub latest: Option<SeedReport>,
    /// Seeds selected that pass 4 cannot draw, if any.
    pub undrawn: Option<UndrawnSeeds>,
}

impl SeedStage {
    /// The stage for `dataset` over the renderer's caches and depth target, or `None` when it has
    /// no land cover (nothing to grow seeds from); pass 4 binds the atmosphere's `air`.
    pub fn new(
        gpu: &Gpu,
        dataset: &Dataset,
        settings: &Settings,
        caches: &Caches,
        (targets, air): (&Targets, &wgpu::BindGroupLayout),
    ) -> Result<Option<Self>, RenderError> {
        let (Some(landcover), Some(landcover_cache)) = (&dataset.manifest.landcover, &caches.landcover)
        else {
            return Ok(None);
        };
        let device = &gpu.device;
        check_capacity(device, settings.seeds.capacity)?;
        let (table, tables, patterns) = seeded_world(settings, landcover)?;
        let undrawn = UndrawnSeeds::find(class_table_name(settings, landcover), &table, settings);
        let pass = SeedSelectPass::new(device, settings, &patterns, &tables, &height_tile_max_m(dataset));
        let bind_group = bind_sources(device, &pass, (caches, landcover_cache), targets);
        let mut compact = CompactPass::new(device, CompactLimits::from(settings))?;
        let compact_bind_group =
            compact.bind_group(device, &CompactInputs { blocks: pass.blocks(), keys: pass.keys() });
        let counters_ring =
            ReadbackRing::new(device, "seed counters", size_of::<SeedCounters>() as u64, DEFAULT_SLOTS);
        let draw = match settings.draw_seeds.impostors.as_str() {
            "" => None,
            dir => {
                Some(draw_pass(gpu, settings, Path::new(dir), &table, &pass, &mut compact, (targets, air))?)
            }
        };
        Ok(Some(Self {
            table,
            tables,
            patterns,
            pass,
            bind_group,
            compact,
            compact_bind_group,
            draw,
            compact_params: CompactParams::default(),
            counters_ring,
            last_frame: None,
            latest: None,
            undrawn,
        }))
    }

    /// Reads `targets`' depth and draws into targets of their size from now on (the frame's
    /// targets made again at another size); the tables, the pipelines and the records stay.
    pub fn resize(&mut self, device: &wgpu::Device, caches: &Caches, targets: &Targets) {
        if let Some(landcover) = &caches.landcover {
            self.bind_group = bind_sources(device, &self.pass, (caches, landcover), targets);
        }
        if let Some((draw, _)) = self.draw.as_mut() {
            draw.resize_multisampled(device, &targets.colour, &targets.depth);
        }
    }

    /// Uploads this frame's cells, and the size of its block table to compaction (each counted as
    /// its pass's).
    pub fn prepare(
        &mut self,
        gpu: &Gpu,
        inputs: &SeedInputs,
        counts: &Counter,
    ) -> Result<&SeedFrame, RenderError> {
        let frame = counts.uploads(&gpu.queue, "seed_select", || self.pass.prepare(&gpu.queue, inputs))?;
        let blocks = frame.blocks();
        self.compact_params =
            counts.uploads(&gpu.queue, "compact", || self.compact.prepare(&gpu.queue, blocks))?;
        Ok(self.last_frame.insert(frame))
    }

    /// Records pass 3 over the cells `prepare` uploaded.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, counting: Counting<'_>) {
        if let Some(frame) = &self.last_frame {
            self.pass.encode(encoder, &self.bind_group, frame, counting);
        }
    }

    /// Records compaction of what pass 3 wrote: the frame's draw order and indirect draws.
    pub fn encode_compact(&self, encoder: &mut wgpu::CommandEncoder, counting: Counting<'_>) {
        if self.last_frame.is_some() {
            self.compact.encode(encoder, &self.compact_bind_group, &self.compact_params, counting);
        }
    }

    /// Species drawn with an impostor, and species not drawn for want of one (all of them without
    /// `draw_seeds.impostors`).
    pub fn species_counts(&self) -> (usize, usize) {
        self.draw.as_ref().map_or((0, self.table.species.len()), |(draw, _)| draw.species_counts())
    }

    /// Writes pass 4's constants for this frame (the terrain's matrix, sun and clouds, the wind),
    /// and, with continuous LOD, the draws' index ranges for this frame's lens (when they change).
    pub fn prepare_draw(
        &mut self,
        gpu: &Gpu,
        settings: &Settings,
        terrain: &TerrainUniforms,
        (wind, earth): (&WindFrame, &EarthNode),
        counts: &Counter,
    ) {
        if let Some((draw, _)) = &self.draw {
            let uniforms = draw_uniforms(settings, terrain, wind, earth);
            counts.uploads(&gpu.queue, "draw_seeds", || draw.prepare(&gpu.queue, &uniforms));
            if let Some(templates) = draw.frame_templates(settings, uniforms.focal_px)
                && templates != self.compact.templates()
            {
                let compact = &mut self.compact;
                counts.uploads(&gpu.queue, "compact", || compact.set_templates(&gpu.queue, &templates));
            }
        }
    }

    /// Records pass 4: the compacted groups drawn into the colour and depth targets.
    pub fn encode_draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (targets, air): ((&wgpu::TextureView, &wgpu::TextureView), &crate::passes::atmosphere::gpu::air::Air),
        (count, counting): (Option<CountedPass<'_>>, Counting<'_>),
    ) {
        if let (Some((draw, bind_group)), Some(_)) = (&self.draw, &self.last_frame) {
            draw.encode(encoder, (bind_group, air), self.compact.draw_args(), targets, (count, counting));
        } else if let Some(count) = count {
            count.nothing(encoder, "draw_seeds", targets.0, targets.1);
        }
    }

    /// Records the copy of pass 3's counters into the staging ring (after the last timed pass:
    /// the CPU-timing fallback submits each pass on its own), unless every slot is in flight.
    pub fn encode_readback(&mut self, encoder: &mut wgpu::CommandEncoder, frame: u64, counts: &Counter) {
        let bytes = size_of::<SeedCounters>() as u64;
        let (cells, ranks) =
            self.last_frame.as_ref().map_or((0, 0), |f| (f.cells.len() as u32, f.uniforms.active_ranks));
        let before = self.counters_ring.copied_bytes();
        self.counters_ring.encode_copy(
            encoder,
            self.pass.counters(),
            bytes,
            CountersTag { frame, cells, ranks },
        );
        counts.read_back("seed_select", self.counters_ring.copied_bytes() - before);
    }

    /// Tells the ring its copy was submitted.
    pub fn submitted(&mut self) {
        self.counters_ring.submitted();
    }

    /// Takes every counter readback that has arrived, keeping the newest.
    pub fn collect(&mut self, device: &wgpu::Device) -> Result<(), GpuError> {
        while let Some(readback) = self.counters_ring.try_take(device)? {
            let CountersTag { frame, cells, ranks } = readback.tag;
            if let Some(&counters) = readback.cast::<SeedCounters>().first() {
                self.latest = Some(SeedReport { frame, cells, ranks, counters });
            }
        }
        Ok(())
    }
}

/// Fails when `seeds.capacity` records do not fit one storage binding of `device`.
fn check_capacity(device: &wgpu::Device, capacity: u32) -> Result<(), RenderError> {
    let record_bytes = size_of::<SeedRecord>() as u64;
    let max_bytes = device.limits().max_storage_buffer_binding_size;
    if u64::from(capacity) * record_bytes > max_bytes {
        return Err(RenderError::SeedCapacity { capacity, max: (max_bytes / record_bytes) as u32 });
    }
    Ok(())
}

/// The name of the class table seeds grow from: `seeds.class_table`, else the land cover's scheme.
pub(super) fn class_table_name<'a>(settings: &'a Settings, landcover: &'a LandcoverLayer) -> &'a str {
    match settings.seeds.class_table.as_str() {
        "" => landcover.scheme.as_str(),
        name => name,
    }
}

/// The class table the land cover's scheme names (or `seeds.class_table`), its species tables for
/// the land cover's coding, and the P generic patterns: what exists, the same for every frame.
fn seeded_world(
    settings: &Settings,
    landcover: &LandcoverLayer,
) -> Result<(ClassTable, SeedTables, SeedPatterns), RenderError> {
    let table = ClassTable::load(class_table_name(settings, landcover))?;
    let seeds = &settings.seeds;
    let tables = SeedTables::new(
        &table,
        &landcover.coding,
        settings.tlm.cell_m,
        seeds.seeds_per_pattern,
        seeds.density_scale,
    )?;
    let patterns =
        SeedPatterns::generate(settings.tlm.corner_colours(), seeds.seeds_per_pattern, settings.tlm.seed);
    Ok((table, tables, patterns))
}

/// Pass 3's bind group over the caches (`landcover` the land cover's) and the frame's depth.
fn bind_sources(
    device: &wgpu::Device,
    pass: &SeedSelectPass,
    (caches, landcover): (&Caches, &TileCache),
    targets: &Targets,
) -> wgpu::BindGroup {
    let sources = SeedSources {
        heights: &caches.heights,
        landcover,
        imagery: &caches.imagery,
        depth: &targets.depth_view,
    };
    pass.bind_group(device, &sources)
}

/// Pass 4 over the impostors in `dir` of `table`'s species, bound to pass 3's records and
/// compaction's order; compaction takes its draw templates.
fn draw_pass(
    gpu: &Gpu,
    settings: &Settings,
    dir: &Path,
    table: &ClassTable,
    pass: &SeedSelectPass,
    compact: &mut CompactPass,
    (targets, air): (&Targets, &wgpu::BindGroupLayout),
) -> Result<(DrawSeedsPass, wgpu::BindGroup), RenderError> {
    let impostors = load_impostors(dir, &table.species)?;
    let choices = LodChoices::of(&settings.draw_seeds, &table.species);
    let prepass = settings.draw_seeds.depth_prepass;
    let mut draw =
        DrawSeedsPass::new(&gpu.device, &gpu.queue, &impostors, &table.species, choices, prepass, air)?;
    if settings.draw_seeds.samples > 1 {
        draw = draw.multisampled(&gpu.device, &targets.colour, &targets.depth);
    }
    compact.set_templates(&gpu.queue, draw.templates());
    let bind_group =
        draw.bind_group(&gpu.device, &DrawSeedsInputs { records: pass.records(), order: compact.order() });
    Ok((draw, bind_group))
}

/// `cells`, each with its mapping from `placed`: its south-west corner's (`cell_m` a side) at
/// height 0.
pub(super) fn placed_cells(
    placed: &mut PlacedView,
    cells: &[SeedCellRef],
    cell_m: f64,
) -> Vec<(SeedCellRef, EarthNode)> {
    let corner =
        |c: &SeedCellRef| DVec3::new(c.address[0] as f64 * cell_m, c.address[1] as f64 * cell_m, 0.0);
    cells.iter().map(|c| (*c, placed.node(corner(c)))).collect()
}

/// The inputs of a frame's seed selection, from a camera `placing` places the grid from, whose
/// nadir's mapping is `nadir` (`ExactPlacing::nadir_node`).
pub(super) fn seed_inputs<'a>(
    settings: &'a Settings,
    dataset: &'a Dataset,
    camera: &'a Camera,
    placing: &ExactPlacing,
    nadir: EarthNode,
    cells: &'a [(SeedCellRef, EarthNode)],
    active_ranks: u32,
) -> SeedInputs<'a> {
    SeedInputs {
        settings,
        dataset,
        camera,
        camera_grid_m: placing.camera_grid_m(),
        viewport_px: [settings.render.width, settings.render.height],
        cells,
        active_ranks,
        nadir,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device whose storage bindings hold at most `max_bytes`, as a smaller adapter's would.
    fn device_binding_at_most(max_bytes: u64) -> wgpu::Device {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&Default::default())).unwrap();
        let required_limits =
            wgpu::Limits { max_storage_buffer_binding_size: max_bytes, ..Default::default() };
        let descriptor = wgpu::DeviceDescriptor { required_limits, ..Default::default() };
        pollster::block_on(adapter.request_device(&descriptor)).unwrap().0
    }

    #[test]
    fn a_seed_capacity_beyond_one_binding_is_a_named_error() {
        let device = device_binding_at_most(1 << 20);
        let fits = (1u32 << 20) / size_of::<SeedRecord>() as u32;
        check_capacity(&device, fits).unwrap();
        let error = check_capacity(&device, fits + 1).unwrap_err();
        assert!(matches!(error, RenderError::SeedCapacity { max, .. } if max == fits), "{error}");
        let said = error.to_string();
        assert!(said.starts_with(&format!("seeds.capacity = {} records does not fit", fits + 1)), "{said}");
    }
}
