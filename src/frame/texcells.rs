//! How it works: the renderer's texcell stage. It exists when `texcells.reach_m` is set, the
//! dataset has land cover, and its class table marks classes as dense that the land cover holds:
//! then each such class's forest sample is read once from `draw_seeds.impostors`/texcells/ (a
//! dense class without one is reported and shows bare ground; no sample at all: no stage, no
//! pass), uploaded, and bound with the land-cover cache. Each frame it rewrites the uniforms if the
//! settings changed them (the band follows `draw_seeds.reach_m`), places patches on the
//! terrain's instances (`passes::texcells::frame`), uploads their slices, and keeps the land-cover
//! tiles under them for the next frame's streaming (a frame late, like the Tile Load Map's).

use std::path::Path;

use glam::DVec3;

use crate::classes::ClassTable;
use crate::config::Settings;
use crate::dataset::{Dataset, TileId};
use crate::gpu::Gpu;
use crate::gpu::counter::Counting;
use crate::gpu::fragments::CountedPass;
use crate::gpu::gpu_types::TexcellUniforms;
use crate::gpu::layout::{TEXCELL_MAX_SAMPLES, TEXCELL_MAX_SLICES};
use crate::passes::terrain::frame::NodeBatches;
use crate::passes::terrain::gpu::{MeshDraw, PreparedNodes, TerrainPass};
use crate::passes::texcells::TexcellsError;
use crate::passes::texcells::dense::DenseCover;
use crate::passes::texcells::frame::{
    Band, SampleShape, Silhouettes, SliceRule, landcover_tiles, place, records, texcell_uniforms,
};
use crate::passes::texcells::gpu::{PreparedTexcells, TexcellsPass};
use crate::streaming::TileCache;
use crate::texcell::{self, ForestSample, tiling};

use super::RenderError;

/// The camera, as the texcell placement sees it.
#[derive(Debug, Clone, Copy)]
pub(super) struct TexcellView {
    /// Camera position in grid space, metres.
    pub camera_grid_m: DVec3,
    /// A pixel's footprint per metre of distance.
    pub metres_per_px_at_1m: f64,
}

/// What the texcell stage drew in a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct TexcellReport {
    /// Node quadrants carrying texcells.
    pub patches: usize,
    /// Regular slice instances drawn.
    pub slices: usize,
    /// Silhouette texcells drawn (one per patch that has one).
    pub silhouettes: usize,
    /// Farthest patches left out because the frame's instances were full.
    pub patches_dropped: usize,
    /// Patches left out because no class with a forest sample lies under them (`DenseCover`).
    pub patches_bare: usize,
}

pub(super) struct TexcellStage {
    pass: TexcellsPass,
    bind_group: wgpu::BindGroup,
    shape: SampleShape,
    band: Band,
    /// The uniforms last written: rewritten when the settings change them (a viewer's knob, a
    /// test's shrinking reaches), so the band follows `draw_seeds.reach_m` like the seeds do.
    uniforms: TexcellUniforms,
    finest_level: u32,
    prepared: PreparedTexcells,
    /// The land-cover tiles under the last frame's patches.
    pub wanted_landcover: Vec<TileId>,
    /// Where the land cover holds forest: patches elsewhere are not drawn.
    dense: Option<DenseCover>,
}

impl TexcellStage {
    /// The stage for `dataset` (`None` when it has nothing to draw texcells with), and the dense
    /// classes the land cover holds that have no forest sample (they show bare ground).
    pub fn new(
        gpu: &Gpu,
        dataset: &Dataset,
        settings: &Settings,
        table: &ClassTable,
        (terrain, air): (&TerrainPass, &wgpu::BindGroupLayout),
        landcover: Option<&TileCache>,
    ) -> Result<(Option<Self>, Vec<u8>), RenderError> {
        let (Some(meta), Some(landcover)) = (&dataset.manifest.landcover, landcover) else {
            return Ok((None, Vec::new()));
        };
        // No impostors: no trees drawn at all, so no forest standing in for them either.
        if !settings.texcells.enabled() || settings.draw_seeds.impostors.is_empty() {
            return Ok((None, Vec::new()));
        }
        let dir = Path::new(&settings.draw_seeds.impostors);
        let palette = &meta.coding.palette;
        let mut samples: Vec<ForestSample> = Vec::new();
        let mut sample_of_class = vec![0u32; palette.len() + 1];
        let mut unbaked = Vec::new();
        for (i, &code) in palette.iter().enumerate() {
            if !table.class(code).is_some_and(|c| c.texcells) {
                continue;
            }
            let Some(sample) = texcell::load(dir, code).map_err(TexcellsError::from)? else {
                unbaked.push(code);
                continue;
            };
            if let Some(first) = samples.first()
                && (first.texels(), first.slice_count()) != (sample.texels(), sample.slice_count())
            {
                return Err(TexcellsError::Mismatch {
                    path: texcell::sample_dir(dir, code),
                    texels: sample.texels(),
                    slices: sample.slice_count(),
                    first_texels: first.texels(),
                    first_slices: first.slice_count(),
                }
                .into());
            }
            samples.push(sample);
            // Palette index i + 1 names this code (0 is "no class").
            sample_of_class[i + 1] = samples.len() as u32;
        }
        let Some(first) = samples.first() else { return Ok((None, unbaked)) };
        let finest = first.slice_count();
        if samples.len() as u32 > TEXCELL_MAX_SAMPLES || finest > TEXCELL_MAX_SLICES {
            let layers = samples.len() as u32 * finest;
            return Err(TexcellsError::TooManyLayers {
                layers,
                max: TEXCELL_MAX_SAMPLES * TEXCELL_MAX_SLICES,
            }
            .into());
        }
        // One slab for all: the tallest class's (a shorter class's slices stretch to it).
        let slab_m = samples.iter().map(|s| f64::from(s.height_m)).fold(0.0, f64::max);
        let shape = SampleShape {
            cell_m: f64::from(first.cell_m),
            slab_m,
            texels: first.texels(),
            finest_slices: finest,
            tile_cells: tiling::sample_cells_word(),
            samples: samples.len() as u32,
            albedo_from_above: std::array::from_fn(|i| {
                samples.get(i).map_or([0.0; 3], ForestSample::albedo_from_above)
            }),
        };
        let band = Band::of(settings);
        // The pixel's footprint comes with the first frame's view, which rewrites the uniforms.
        let uniforms = texcell_uniforms(settings, dataset, &band, &shape, 0.0);
        let pass = TexcellsPass::new(
            &gpu.device,
            &gpu.queue,
            (terrain, air),
            settings.terrain.node_cells,
            &samples,
            &sample_of_class,
            &uniforms,
        )?;
        let bind_group = pass.bind_group(&gpu.device, landcover);
        let stage = Self {
            pass,
            bind_group,
            shape,
            band,
            uniforms,
            finest_level: finest.ilog2(),
            prepared: PreparedTexcells::default(),
            wanted_landcover: Vec::new(),
            dense: DenseCover::new(dataset, &sample_of_class),
        };
        Ok((Some(stage), unbaked))
    }

    /// Places this frame's patches on the terrain's uploaded instances and uploads their slices.
    pub fn prepare(
        &mut self,
        gpu: &Gpu,
        settings: &Settings,
        dataset: &Dataset,
        batches: &NodeBatches,
        nodes: &PreparedNodes,
        view: &TexcellView,
    ) -> TexcellReport {
        let TexcellView { camera_grid_m, metres_per_px_at_1m } = *view;
        let band = Band::of(settings);
        let uniforms = texcell_uniforms(settings, dataset, &band, &self.shape, metres_per_px_at_1m);
        if bytemuck::bytes_of(&uniforms) != bytemuck::bytes_of(&self.uniforms) {
            self.pass.write_uniforms(&gpu.queue, &uniforms);
            (self.band, self.uniforms) = (band, uniforms);
        }
        let shape = &self.shape;
        let rule = SliceRule {
            metres_per_px_at_1m,
            texel_m: REFERENCE_SPAN * shape.cell_m / f64::from(shape.texels),
            slab_m: shape.slab_m,
            slice_px: settings.texcells.slice_px,
            finest_level: self.finest_level,
        };
        let silhouettes = Silhouettes::of(settings);
        let mut patches = place(
            batches,
            |q, i| nodes.instance(q, i),
            camera_grid_m,
            &self.band,
            &rule,
            silhouettes.as_ref(),
        );
        // A silhouette's rays run through the slab beyond its patch's footprint: it is always drawn.
        let placed = patches.len();
        if let Some(dense) = self.dense.as_mut() {
            patches.retain(|p| {
                let (min_m, max_m) = (p.bounds.min_m, p.bounds.max_m);
                p.kinds.silhouette || dense.any_dense(dataset, [min_m.x, min_m.y], [max_m.x, max_m.y])
            });
        }
        let (records, dropped) = records(&patches, self.finest_level, camera_grid_m.z, shape.slab_m);
        self.wanted_landcover = landcover_tiles(dataset, &patches);
        self.prepared = self.pass.prepare(&gpu.queue, &records);
        let silhouettes = patches[dropped..].iter().filter(|p| p.kinds.silhouette).count();
        TexcellReport {
            patches: patches.len() - dropped,
            slices: records.len() - silhouettes,
            silhouettes,
            patches_dropped: dropped,
            patches_bare: placed - patches.len(),
        }
    }

    /// Draws the frame's texcells over `colour`, counted through `counting` (and `count`).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (mesh, air): (MeshDraw<'_>, &crate::passes::atmosphere::gpu::air::Air),
        targets: (&wgpu::TextureView, &wgpu::TextureView),
        (count, counting): (Option<CountedPass<'_>>, Counting<'_>),
    ) {
        self.pass.encode(encoder, (mesh, &self.bind_group, air), targets, self.prepared, (count, counting));
    }
}

/// Ground cells along the forest sample's side.
const REFERENCE_SPAN: f64 = tiling::REFERENCE_CELLS as f64;
