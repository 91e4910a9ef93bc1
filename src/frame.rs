//! How it works: `Renderer` owns the GPU resources of one dataset (caches, passes, targets) and
//! `render` runs one frame as the list of its passes. Each step says why it is there; the
//! mechanics live in the pass modules.

use glam::{DVec3, Vec4};
use thiserror::Error;

use crate::camera::{Camera, CameraError, Frustum};
use crate::config::Settings;
use crate::dataset::{Dataset, IMAGERY_MIPS, LayerSpec, PackError, TileId};
use crate::gpu::gpu_types::{TerrainNode, TerrainUniforms};
use crate::gpu::readback::read_texture;
use crate::gpu::{Gpu, GpuError, PassTiming, Profiler};
use crate::shaders::MAX_LEVELS;
use crate::streaming::{CacheStats, Footprint, TileCache, wanted_cell_tiles};
use crate::terrain::select::{Lods, NodeBounds, Selected, select};
use crate::terrain::{COLOUR_FORMAT, DEPTH_FORMAT, NodeBatches, TerrainPass};

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
}

pub struct Renderer {
    pub gpu: Gpu,
    pub dataset: Dataset,
    pub settings: Settings,
    pub profiler: Profiler,
    terrain: TerrainPass,
    heights: TileCache,
    imagery: TileCache,
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
        let device = &gpu.device;
        let terrain = TerrainPass::new(device, &settings, gpu.info.device_type == wgpu::DeviceType::Cpu);
        let heights = TileCache::new(
            device,
            "height cache",
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
                LayerSpec::imagery([1, 1]).pyramid,
                IMAGERY_MIPS,
                wgpu::TextureFormat::Rgba8UnormSrgb,
                1,
            ),
        };
        let terrain_bindings = terrain.bind_group(device, &heights, &imagery);
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
        let h = &dataset.manifest.height;
        let bounds = NodeBounds::new([h.min_m, h.max_m]);
        let profiler = Profiler::new(&gpu, settings.gpu.timestamps);
        Ok(Self {
            gpu,
            dataset,
            settings,
            profiler,
            terrain,
            heights,
            imagery,
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
        let (width, height) = (self.settings.render.width, self.settings.render.height);
        let clip_from_view_world = camera.clip_from_view(width, height)? * camera.view_from_world();
        let frustum = Frustum::from_clip(clip_from_view_world);
        let origin = self.dataset.manifest.origin_m;
        let camera_grid_m = camera.position_m - DVec3::new(origin[0], origin[1], 0.0);
        let mut report = FrameReport { frame: self.frame, ..Default::default() };

        // Terrain LOD: choose the nodes whose triangles keep their target size on screen.
        let h = &self.dataset.manifest.height;
        let t = &self.settings.terrain;
        let lods = Lods::new(
            self.dataset.height.pyramid,
            h.spacing_m,
            t.node_cells,
            camera.metres_per_pixel(1.0, height),
            t.triangle_px,
            t.morph_fraction,
        );
        let selected = self.profiler.cpu("terrain_select", || {
            let (dataset, bounds) = (&self.dataset, &mut self.bounds);
            select(&lods, camera_grid_m, &frustum, &mut |node| {
                bounds.get(&lods, node, |tile| dataset.height_tile(tile).ok())
            })
        });

        // Residency: the height tiles those nodes read, and the imagery their pixels ask for.
        let frame = self.frame;
        let (dataset, heights, imagery) = (&self.dataset, &mut self.heights, &mut self.imagery);
        let queue = &self.gpu.queue;
        let wanted_heights = height_tiles(&lods, &selected);
        let wanted_imagery = self.profiler.cpu("imagery_wants", || {
            imagery_tiles(
                dataset,
                &lods,
                &selected,
                camera,
                camera_grid_m,
                height,
                self.settings.imagery.lod_bias,
            )
        });
        let (height_stats, imagery_stats) = self.profiler.cpu("uploads", || {
            let height_stats =
                heights.update(queue, &wanted_heights, frame, |id| dataset.height.tile_bytes(id));
            let imagery_stats = match &dataset.imagery {
                Some(layer) => imagery.update(queue, &wanted_imagery, frame, |id| layer.tile_bytes(id)),
                None => CacheStats::default(),
            };
            (height_stats, imagery_stats)
        });
        report.height = height_stats;
        report.imagery = imagery_stats;

        // Instances: camera-relative node origins, subtracted in f64.
        let mut batches = NodeBatches::default();
        for s in &selected {
            let Some(slot) = self.heights.slot_of(lods.tile_of(s.node)) else {
                report.nodes_dropped += 1;
                continue;
            };
            let size = lods.node_m(s.node.lod);
            let lod = s.node.lod as usize;
            let node = TerrainNode {
                origin_rel_m: [
                    (f64::from(s.node.x) * size - camera_grid_m.x) as f32,
                    (f64::from(s.node.y) * size - camera_grid_m.y) as f32,
                ],
                cell_m: (size / f64::from(lods.cells)) as f32,
                height_slot: slot,
                sample_offset: lods.sample_offset(s.node),
                morph_start_m: lods.morph_start_m[lod].min(f64::from(f32::MAX)) as f32,
                morph_end_m: lods.range_m[lod].min(f64::from(f32::MAX)) as f32,
                cells_inside: lods.cells_inside(s.node).map(|c| c as f32),
            };
            for q in 0..4 {
                if s.quadrants & (1 << q) != 0 {
                    batches.by_quadrant[q].push(node);
                }
            }
        }
        report.nodes_drawn = batches.len();
        let uniforms = self.uniforms(camera_grid_m, clip_from_view_world.as_mat4());
        let prepared = self.terrain.prepare(&self.gpu.queue, &uniforms, &batches);

        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        let colour = self.colour.create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        // Terrain and depth: the ground every later pass stands on and is occluded by.
        self.profiler.pass(&self.gpu, &mut encoder, "terrain", |encoder| {
            self.terrain.encode(encoder, &self.terrain_bindings, &colour, &depth, SKY_LINEAR, &prepared)
        })?;
        self.profiler.resolve(&mut encoder);
        self.gpu.queue.submit([encoder.finish()]);
        self.profiler.end_frame();
        self.gpu.device.poll(wgpu::PollType::Poll).map_err(GpuError::from)?;
        while let Some(timings) = self.profiler.finished_frame(&self.gpu) {
            self.last_timings = timings;
        }
        self.gpu.check()?;
        self.frame += 1;
        Ok(report)
    }

    fn uniforms(&self, camera_grid_m: DVec3, clip: glam::Mat4) -> TerrainUniforms {
        let r = &self.settings.render;
        let manifest = &self.dataset.manifest;
        let (azimuth, elevation) = (r.sun_azimuth_deg.to_radians(), r.sun_elevation_deg.to_radians());
        let sun =
            DVec3::new(azimuth.sin() * elevation.cos(), azimuth.cos() * elevation.cos(), elevation.sin());
        let half_spacing = 0.5 * manifest.height.spacing_m;
        let mut uniforms = TerrainUniforms {
            clip_from_view_world: clip.to_cols_array_2d(),
            sun_dir: sun.as_vec3().extend(0.0).to_array(),
            haze: Vec4::new(
                SKY_LINEAR[0] as f32,
                SKY_LINEAR[1] as f32,
                SKY_LINEAR[2] as f32,
                r.haze_half_distance_m as f32,
            )
            .to_array(),
            camera_grid_m: camera_grid_m.as_vec3().extend(0.0).to_array(),
            height_range_m: [manifest.height.min_m, manifest.height.max_m],
            node_cells: self.settings.terrain.node_cells,
            has_imagery: u32::from(self.dataset.imagery.is_some()),
            imagery_frame: [0.0; 4],
            imagery_levels: [[0; 4]; MAX_LEVELS as usize],
            imagery_level_count: 1,
            _pad: [0; 3],
        };
        if let (Some(layer), Some(meta)) = (&self.dataset.imagery, &manifest.imagery) {
            let p = &layer.pyramid;
            uniforms.imagery_frame = [
                -half_spacing as f32,
                -half_spacing as f32,
                meta.texel_m as f32,
                self.settings.imagery.lod_bias as f32,
            ];
            for level in 0..p.levels {
                let [nx, ny] = p.tiles_at(level);
                let first = p.tile_index(TileId::new(level, 0, 0)).unwrap_or_default() as u32;
                uniforms.imagery_levels[level as usize] = [first, nx, ny, 0];
            }
            uniforms.imagery_level_count = p.levels;
        }
        uniforms
    }

    /// The last frame's colour, as an sRGB image.
    pub fn read_colour(&self) -> Result<image::RgbaImage, RenderError> {
        let bytes = read_texture(&self.gpu, &self.colour, wgpu::TextureAspect::All, 4)?;
        let (w, h) = (self.colour.width(), self.colour.height());
        image::RgbaImage::from_raw(w, h, bytes)
            .ok_or_else(|| RenderError::Gpu(GpuError::Validation("readback size mismatch".into())))
    }

    /// The last frame's depth (reversed-Z: 1 at the near plane, 0 for the sky), top row first.
    pub fn read_depth(&self) -> Result<Vec<f32>, RenderError> {
        let bytes = read_texture(&self.gpu, &self.depth, wgpu::TextureAspect::DepthOnly, 4)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

/// The height tiles the selected nodes read, coarse first (they stand in for everything finer).
fn height_tiles(lods: &Lods, selected: &[Selected]) -> Vec<TileId> {
    let mut tiles: Vec<TileId> = selected.iter().map(|s| lods.tile_of(s.node)).collect();
    tiles.sort_by(|a, b| b.level.cmp(&a.level).then(a.cmp(b)));
    tiles.dedup();
    tiles
}

/// The imagery tiles the selected nodes' pixels ask for.
fn imagery_tiles(
    dataset: &Dataset,
    lods: &Lods,
    selected: &[Selected],
    camera: &Camera,
    camera_grid_m: DVec3,
    height_px: u32,
    lod_bias: f64,
) -> Vec<TileId> {
    let (Some(layer), Some(meta)) = (&dataset.imagery, &dataset.manifest.imagery) else {
        return Vec::new();
    };
    let half_spacing = 0.5 * dataset.manifest.height.spacing_m;
    let footprints: Vec<Footprint> = selected
        .iter()
        .map(|s| {
            let size = lods.node_m(s.node.lod);
            let min = [f64::from(s.node.x) * size, f64::from(s.node.y) * size];
            let max = [min[0] + size, min[1] + size];
            let nearest = DVec3::new(
                camera_grid_m.x.clamp(min[0], max[0]),
                camera_grid_m.y.clamp(min[1], max[1]),
                camera_grid_m.z.clamp(
                    f64::from(dataset.manifest.height.min_m),
                    f64::from(dataset.manifest.height.max_m),
                ),
            );
            let distance_m = (nearest - camera_grid_m).length().max(camera.near_m);
            Footprint {
                min_m: min.map(|v| v + half_spacing),
                max_m: max.map(|v| v + half_spacing),
                pixel_m: camera.metres_per_pixel(distance_m, height_px),
                distance_m,
            }
        })
        .collect();
    wanted_cell_tiles(&layer.pyramid, meta.texel_m, lod_bias, &footprints)
}
