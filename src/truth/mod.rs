//! How it works: the ground truth (DESIGN.md, "Accuracy, and the speed trade"): what the scene
//! really looks like, offline and slow, the reference every preset is judged against. It is never
//! the thing measured, so it shares the scene's definition (the seeded world, the models, the
//! materials and lighting) but none of the shortcuts a preset takes:
//! - **supersampled**: the view is rendered at `supersample`² samples per pixel (4 × 4 by
//!   default), box-filtered in linear light, so alpha-tested leaves and far texels do not alias;
//! - **all tiles at their finest level**: every tile of every layer is loaded and pinned
//!   (`Renderer::pin_everything`) and the terrain mesh is the finest everywhere (the LOD
//!   selection's triangle target made vanishingly small); imagery is filtered by each sample's own
//!   footprint, from the finest level;
//! - **every seed the land cover grows** at full density (`seeds.density_scale` 1) within
//!   `reach_m` of the camera (`scene`: the exact oracle's seeds with the truth's culls, f64), each
//!   drawn as its full glTF mesh through pass 4's own vertex stage and material (`fs_truth`:
//!   no billboard clouds, no fades), culled by nothing but the view's projection and the depth
//!   test;
//! - **a seed-id buffer**: per sample, which seed it shows, and the depth; `visibility` turns them
//!   into the any-part oracle (a seed is visible when any of its samples survives).
//!
//! The seeded world (patterns per cell, ranks, sizes) is the settings' own, so the truth's seeds
//! and a preset's share their identities (cell address, rank): the truth of a preset that grows
//! half the density, or reaches 2 km instead of 4, has the seeds it leaves out. Presets with
//! different patterns grow different (equally dense) forests: their images are compared with one
//! truth, their selections with the truth of their own world.

#[cfg(feature = "flip")]
pub mod compare;
pub mod files;
pub mod scene;
pub mod visibility;

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::camera::Camera;
use crate::config::Settings;
use crate::dataset::{Dataset, PackError};
use crate::frame::{RenderError, Renderer};
use crate::gpu::readback::read_texture;
use crate::gpu::resources::buffer_init;
use crate::gpu::{Gpu, GpuError};
use crate::passes::atmosphere::gpu::air::AirVariants;
use crate::passes::draw_seeds::frame::{draw_uniforms, load_impostors};
use crate::passes::draw_seeds::gpu::{DrawSeedsInputs, DrawSeedsPass, SEED_ID_FORMAT};
use crate::passes::draw_seeds::{DrawSeedsError, LodChoices};
use crate::reference::oracle::{Culls, OracleCounts, OracleError, OracleSeed, judge_seeds};
use scene::TruthScene;
use visibility::samples_per_seed;

/// The truth's reach when none is given, metres: a 10 m tree there stands about 2 pixels tall in
/// a 720-pixel, 60° view. Beyond it a forest is texture, not trees, and no preset draws seeds.
pub const DEFAULT_REACH_M: f64 = 4000.0;
/// The terrain LOD selection's triangle target for the truth, pixels: small enough that every
/// node within the far plane is at the finest level.
const FINEST_TRIANGLE_PX: f64 = 1e-3;
/// Pass 4's LOD reach for the truth: every seed is LOD 0, never in a fade band.
const NO_FADE_REACH_M: f32 = 1e30;

/// Why the ground truth could not be rendered.
#[derive(Debug, Error)]
pub enum TruthError {
    /// The renderer failed: the viewport (supersampled) or the caches (every tile) do not fit, a
    /// pack could not be read, the GPU failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The seeds could not be enumerated.
    #[error(transparent)]
    Oracle(#[from] OracleError),
    /// The seeds' models could not be loaded or uploaded.
    #[error(transparent)]
    DrawSeeds(#[from] DrawSeedsError),
    /// An imagery tile could not be read for a seed's ground colour.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// Reading the targets back failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The dataset grows seeds but no impostor folder was given.
    #[error(
        "the ground truth draws the seeds' meshes: give an impostor folder (--impostors or draw_seeds.impostors)"
    )]
    NoImpostors,
    /// A species that grows in view has no mesh to draw (no model in the impostor folder, or a
    /// model without one).
    #[error("species {species} (model {model}) grows in view but {dir} has no mesh for it")]
    NoMesh {
        /// The species' name.
        species: String,
        /// Its model's name.
        model: String,
        /// The impostor folder.
        dir: PathBuf,
    },
    /// `draw_truth` was given a renderer that has not rendered a frame.
    #[error("the truth draws over a rendered frame: render the view first")]
    NoFrame,
    /// `supersample` must be 1 or more.
    #[error("supersample must be 1 or more")]
    Supersample,
}

/// How the truth is rendered.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthOptions {
    /// Samples per pixel along each axis.
    pub supersample: u32,
    /// Seeds grow out to this distance from the camera, metres.
    pub reach_m: f64,
    /// The impostor folder whose meshes the seeds are drawn with; empty: `draw_seeds.impostors`.
    pub impostors: PathBuf,
}

impl Default for TruthOptions {
    fn default() -> Self {
        Self { supersample: 4, reach_m: DEFAULT_REACH_M, impostors: PathBuf::new() }
    }
}

/// A view's ground truth.
pub struct Truth {
    /// The image's size, pixels (`render.width`, `render.height`).
    pub size_px: [u32; 2],
    /// Samples per pixel along each axis.
    pub supersample: u32,
    /// The image, box-filtered from the samples (sRGB).
    pub colour: image::RgbaImage,
    /// The same without the seeds: the ground alone.
    pub ground: image::RgbaImage,
    /// Per sample (`size_px × supersample` along each axis, top row first): 0 for terrain or
    /// sky, else the index + 1 of the seed in `seeds`.
    pub seed_ids: Vec<u32>,
    /// Per sample, reversed-Z depth (1 at the near plane, 0 for the sky).
    pub depth: Vec<f32>,
    /// The seeds drawn, grouped by species.
    pub seeds: Vec<OracleSeed>,
    /// Per seed, the samples that show it: visible when at least one does.
    pub samples: Vec<u64>,
    /// What the seeds' enumeration counted (candidates, culled by class, rule, reach, frustum).
    pub counts: OracleCounts,
}

/// The settings the truth renders with: `settings` at `supersample`² the viewport, full density,
/// the finest terrain everywhere, caches for every tile of `dataset`, no seeds of its own.
pub fn truth_settings(settings: &Settings, dataset: &Dataset, supersample: u32) -> Settings {
    let mut s = settings.clone();
    s.render.width *= supersample;
    s.render.height *= supersample;
    s.terrain.triangle_px = FINEST_TRIANGLE_PX;
    s.seeds.density_scale = 1.0;
    s.draw_seeds.impostors.clear();
    // Every tree is its mesh out to the truth's reach: no forest stands in for them.
    s.texcells.reach_m = 0.0;
    s.draw_seeds.continuous_lod = false;
    let tiles = |count: u64| u32::try_from(count).unwrap_or(u32::MAX);
    s.cache.height_slots = tiles(dataset.height.pyramid.tile_count());
    if let Some(layer) = &dataset.imagery {
        s.cache.imagery_slots = tiles(layer.pyramid.tile_count());
    }
    if let Some(layer) = &dataset.landcover {
        s.cache.landcover_slots = tiles(layer.pyramid.tile_count());
    }
    s
}

/// Renders the ground truth of `camera` over `dataset` with the world of `settings`.
pub fn render_truth(
    gpu: Gpu,
    dataset: Dataset,
    settings: &Settings,
    camera: &Camera,
    options: &TruthOptions,
) -> Result<Truth, TruthError> {
    TruthRenderer::new(gpu, dataset, settings, options)?.render(camera)
}

/// The ground truth of one seeded world from any number of views (a flight, a sweep's poses):
/// every tile loaded and pinned once, the seeds' meshes uploaded on first use and kept.
pub struct TruthRenderer {
    renderer: Renderer,
    meshes: MeshDrawer,
    options: TruthOptions,
}

impl TruthRenderer {
    /// A renderer with `truth_settings` over `dataset`, every tile pinned; the seeds' meshes come
    /// from `options.impostors`, else `settings`' `draw_seeds.impostors`.
    pub fn new(
        gpu: Gpu,
        dataset: Dataset,
        settings: &Settings,
        options: &TruthOptions,
    ) -> Result<Self, TruthError> {
        if options.supersample == 0 {
            return Err(TruthError::Supersample);
        }
        let impostors = match options.impostors.as_os_str().is_empty() {
            true => PathBuf::from(&settings.draw_seeds.impostors),
            false => options.impostors.clone(),
        };
        let truth = truth_settings(settings, &dataset, options.supersample);
        let mut renderer = Renderer::new(gpu, dataset, truth)?;
        renderer.pin_everything()?;
        Ok(Self { renderer, meshes: MeshDrawer::new(impostors), options: options.clone() })
    }

    /// Sets the scene's time (wind, clouds) of the truths rendered from now on (`Renderer::set_time_s`).
    pub fn set_time_s(&mut self, time_s: f64) {
        self.renderer.set_time_s(time_s);
    }

    /// The truth of the view from `camera`.
    pub fn render(&mut self, camera: &Camera) -> Result<Truth, TruthError> {
        let renderer = &mut self.renderer;
        renderer.render_resolved(camera)?;
        let (seeds, counts) = match renderer.oracle_inputs(camera) {
            Some(inputs) => judge_seeds(
                &inputs,
                Culls { reach_m: Some(self.options.reach_m), occlusion: false, frustum: true },
            )?,
            None => (Vec::new(), OracleCounts::default()),
        };
        let mut truth = draw_seeds(renderer, camera, seeds, &mut self.meshes, self.options.supersample)?;
        truth.counts = counts;
        Ok(truth)
    }
}

/// Pass 4 set up to draw the seeds' full meshes with the truth's pipeline, built on first use.
struct MeshDrawer {
    dir: PathBuf,
    built: Option<(DrawSeedsPass, AirVariants<wgpu::RenderPipeline>)>,
}

impl MeshDrawer {
    fn new(dir: PathBuf) -> Self {
        Self { dir, built: None }
    }

    /// The pass over the models of `species` (loaded from `dir` now, the first time) and its
    /// truth pipeline.
    fn get(
        &mut self,
        gpu: &Gpu,
        species: &[crate::classes::Species],
        air: &wgpu::BindGroupLayout,
    ) -> Result<&(DrawSeedsPass, AirVariants<wgpu::RenderPipeline>), TruthError> {
        let built = match self.built.take() {
            Some(built) => built,
            None => {
                if self.dir.as_os_str().is_empty() {
                    return Err(TruthError::NoImpostors);
                }
                let impostors = load_impostors(&self.dir, species)?;
                // Every seed its whole mesh: no continuous LOD; drawn with `truth_pipeline`, not the
                // frame's draws, so no prepass.
                let choices = LodChoices::default();
                let draw =
                    DrawSeedsPass::new(&gpu.device, &gpu.queue, &impostors, species, choices, false, air)?;
                let pipeline = draw.truth_pipeline(&gpu.device);
                (draw, pipeline)
            }
        };
        Ok(self.built.insert(built))
    }
}

/// Draws `seeds` (each its full mesh) over the settled frame of `renderer` (made with
/// `truth_settings`, rendered from `camera`) and reads the truth back. Tests hand-build `seeds`.
pub fn draw_truth(
    renderer: &Renderer,
    camera: &Camera,
    seeds: Vec<OracleSeed>,
    impostor_dir: &Path,
    supersample: u32,
) -> Result<Truth, TruthError> {
    draw_seeds(renderer, camera, seeds, &mut MeshDrawer::new(impostor_dir.to_owned()), supersample)
}

fn draw_seeds(
    renderer: &Renderer,
    camera: &Camera,
    seeds: Vec<OracleSeed>,
    meshes: &mut MeshDrawer,
    supersample: u32,
) -> Result<Truth, TruthError> {
    let canvas = renderer.last_canvas().ok_or(TruthError::NoFrame)?;
    let device = &renderer.gpu.device;
    // The seeds are drawn over copies: the renderer's own targets keep its frame.
    let scratch = |label, like: &wgpu::Texture, format| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: like.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            // Bound too: the display pass shows the colour (`Renderer::display_light`).
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    };
    let colour = scratch("truth colour", canvas.colour, canvas.colour.format());
    let depth = scratch("truth depth", canvas.depth, canvas.depth.format());
    let ids_texture = scratch("truth seed ids", canvas.colour, SEED_ID_FORMAT);
    let mut encoder = device.create_command_encoder(&Default::default());
    for (from, to) in [(canvas.colour, &colour), (canvas.depth, &depth)] {
        encoder.copy_texture_to_texture(from.as_image_copy(), to.as_image_copy(), from.size());
    }
    renderer.gpu.queue.submit([encoder.finish()]);
    let scene = match (renderer.class_table(), renderer.seed_world()) {
        (Some(table), Some((tables, _))) if !seeds.is_empty() => {
            let placing = renderer.exact_placing(camera);
            Some((table, TruthScene::new(&renderer.dataset, &renderer.settings, tables, &placing, seeds)?))
        }
        _ => None,
    };
    if let Some((table, scene)) = &scene {
        let (gpu, settings) = (&renderer.gpu, &renderer.settings);
        let dir = meshes.dir.clone();
        let (draw, pipeline) = meshes.get(gpu, &table.species, canvas.air.layout())?;
        let wind = renderer.wind_frame(camera);
        let earth = renderer.exact_placing(camera).nadir_node();
        let mut uniforms = draw_uniforms(settings, canvas.terrain, &wind, &earth);
        uniforms.draw_reach_m = [NO_FADE_REACH_M; 4];
        // Its samples average a small seed's detail themselves: no shortcut to its mean.
        uniforms.prefilter_small = 0;
        draw.prepare(&gpu.queue, &uniforms);
        let mut draws = Vec::new();
        for (species, range) in &scene.species_ranges {
            let Some(mesh) = draw.mesh_of(*species) else {
                let s = &table.species[*species as usize];
                let (species, model) = (s.name.clone(), s.model.clone());
                return Err(TruthError::NoMesh { species, model, dir });
            };
            draws.push((mesh, range.clone()));
        }
        let storage = wgpu::BufferUsages::STORAGE;
        let records =
            buffer_init(&gpu.device, "truth records", bytemuck::cast_slice(&scene.records), storage);
        let identity: Vec<u32> = (0..scene.records.len() as u32).collect();
        let order = buffer_init(&gpu.device, "truth order", bytemuck::cast_slice(&identity), storage);
        let bind_group = draw.bind_group(&gpu.device, &DrawSeedsInputs { records: &records, order: &order });
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let ids_view = ids_texture.create_view(&Default::default());
        let colour_view = colour.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        {
            let keep = wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store };
            let clear = wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            };
            let attachment = |view, ops| {
                Some(wgpu::RenderPassColorAttachment { view, depth_slice: None, resolve_target: None, ops })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("truth seeds"),
                color_attachments: &[attachment(&colour_view, keep), attachment(&ids_view, clear)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            draw.encode_meshes(
                &mut pass,
                pipeline.get(canvas.air),
                (&bind_group, canvas.air.group()),
                &draws,
            );
        }
        gpu.queue.submit([encoder.finish()]);
        gpu.check()?;
    }
    let read = |texture, aspect| read_texture(&renderer.gpu, texture, aspect, 4);
    let seed_ids: Vec<u32> = match scene {
        Some(_) => bytemuck::pod_collect_to_vec(&read(&ids_texture, wgpu::TextureAspect::All)?),
        None => vec![0; (colour.width() * colour.height()) as usize],
    };
    let seeds = scene.map(|(_, s)| s.seeds).unwrap_or_default();
    let samples = samples_per_seed(&seed_ids, seeds.len());
    let colour = box_filter(&renderer.display_light(&colour)?, supersample);
    let ground = box_filter(&renderer.read_colour()?, supersample);
    let depth = bytemuck::pod_collect_to_vec(&read(&depth, wgpu::TextureAspect::DepthOnly)?);
    Ok(Truth {
        size_px: [colour.width(), colour.height()],
        supersample,
        colour,
        ground,
        seed_ids,
        depth,
        seeds,
        samples,
        counts: OracleCounts::default(),
    })
}

/// An sRGB-encoded byte in linear light (IEC 61966-2-1).
fn srgb_to_linear(byte: u8) -> f64 {
    let c = f64::from(byte) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// `image` (sRGB) reduced by `factor` along each axis, each pixel the mean of its samples in
/// linear light.
pub fn box_filter(image: &image::RgbaImage, factor: u32) -> image::RgbaImage {
    let to_linear: Vec<f64> = (0..=255u8).map(srgb_to_linear).collect();
    let to_srgb = |l: f64| {
        let c = if l <= 0.0031308 { l * 12.92 } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    let factor = factor.max(1);
    let (w, h) = (image.width() / factor, image.height() / factor);
    let n = f64::from(factor * factor);
    image::RgbaImage::from_fn(w, h, |x, y| {
        let mut sum = [0.0f64; 4];
        for sy in 0..factor {
            for sx in 0..factor {
                let p = image.get_pixel(x * factor + sx, y * factor + sy).0;
                for c in 0..3 {
                    sum[c] += to_linear[p[c] as usize];
                }
                sum[3] += f64::from(p[3]);
            }
        }
        image::Rgba([
            to_srgb(sum[0] / n),
            to_srgb(sum[1] / n),
            to_srgb(sum[2] / n),
            (sum[3] / n).round() as u8,
        ])
    })
}
