//! The Tile Load Map's CPU half for one frame: its inputs, and the uniforms and ring spans the GPU
//! pass and its twin read (`TlmFrame`), computed in f64 and rounded once.

use glam::{DMat4, DVec3};

use crate::camera::Camera;
use crate::config::{ImagerySettings, TlmSettings};
use crate::dataset::{Dataset, TileId};
use crate::earth::horizon::{EarthBend, HorizonCone};
use crate::earth::placing::ExactPlacing;
use crate::gpu::gpu_types::{EarthNode, TlmCell, TlmRing, TlmSpan, TlmUniforms};
use crate::gpu::layout::{MAX_LEVELS, TLM_MAX_RINGS};
use crate::passes::terrain::select::Lods;
use crate::streaming::page_levels;

use super::TlmError;
use super::layout::{TlmLayout, height_level};

/// Height ranges of every height tile, in `Pyramid::tile_index` order: the pass's per-dataset input.
/// Each is the union of the pack's conservative range (every level-0 sample under the tile) over the
/// tile and its eight neighbours: a coarse mesh near a tile's edge interpolates towards samples of
/// the neighbour, and the box must hold that surface too. A tile whose range cannot be read gets
/// the dataset's whole range.
pub fn height_tile_ranges(dataset: &Dataset) -> Vec<[f32; 2]> {
    let pyramid = &dataset.height.pyramid;
    let whole = [dataset.manifest.height.min_m, dataset.manifest.height.max_m];
    let own: Vec<[f32; 2]> = pyramid.tiles().map(|id| dataset.height_range(id).unwrap_or(whole)).collect();
    pyramid
        .tiles()
        .map(|id| {
            let [nx, ny] = pyramid.tiles_at(id.level);
            let mut range = [f32::INFINITY, f32::NEG_INFINITY];
            for y in id.y.saturating_sub(1)..=(id.y + 1).min(ny - 1) {
                for x in id.x.saturating_sub(1)..=(id.x + 1).min(nx - 1) {
                    let index = pyramid.tile_index(TileId::new(id.level, x, y)).unwrap_or_default() as usize;
                    range = [range[0].min(own[index][0]), range[1].max(own[index][1])];
                }
            }
            range
        })
        .collect()
}

/// The imagery layer as the TLM sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TlmImagery {
    /// Texel edge at level 0, metres.
    pub texel_m: f64,
    /// Levels of its pyramid, 0 the finest.
    pub levels: u32,
    /// `imagery.lod_bias`, log2 texels.
    pub lod_bias: f64,
}

impl TlmImagery {
    /// `dataset`'s imagery as the TLM sees it, with the imagery settings' bias; `None` without.
    pub fn of(dataset: &Dataset, settings: &ImagerySettings) -> Option<Self> {
        dataset.manifest.imagery.as_ref().map(|i| Self {
            texel_m: i.texel_m,
            levels: i.pyramid.levels,
            lod_bias: settings.lod_bias,
        })
    }
}

/// Where the TLM's cells lie: on the Earth (their boxes bent onto it, culled by its horizon),
/// or on the flat sheet (`TlmEarth::default()`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TlmEarth {
    /// How a cell's box bends.
    pub bend: EarthBend,
    /// The horizon the cells are culled by; `None`: none is.
    pub horizon: Option<HorizonCone>,
}

impl TlmEarth {
    /// The cells as `placing` draws `dataset` (from the frame's camera, whose nadir's mapping is
    /// `nadir`: `ExactPlacing::nadir_node`), culled by the horizon when `horizon_culling`
    /// (`terrain.horizon_culling`).
    pub fn of(placing: &ExactPlacing, nadir: &EarthNode, dataset: &Dataset, horizon_culling: bool) -> Self {
        let h = &dataset.manifest.height;
        let max_abs_height_m = f64::from(h.min_m.abs().max(h.max_m.abs()));
        let horizon = placing.horizon(f64::from(h.min_m)).filter(|_| horizon_culling);
        Self { bend: EarthBend::of(nadir, max_abs_height_m), horizon }
    }
}

/// What one frame's TLM is computed from.
pub struct TlmInputs<'a> {
    /// The `[tlm]` settings: radial bands, patterns, seed and occlusion tolerance.
    pub settings: &'a TlmSettings,
    /// The frame's rings around the camera.
    pub layout: &'a TlmLayout,
    /// The frame's camera: its projection gives the frustum planes and the imagery footprint.
    pub camera: &'a Camera,
    /// Camera position in grid space (CRS position − `Manifest::origin_m`), metres.
    pub camera_grid_m: DVec3,
    /// The depth target's size, pixels.
    pub viewport_px: [u32; 2],
    /// The terrain's LODs this frame (ranges, height pyramid and spacing).
    pub lods: &'a Lods,
    /// The dataset's imagery, `None` without: cells then ask for no imagery levels.
    pub imagery: Option<TlmImagery>,
    /// Levels of the depth pyramid the occlusion test may read.
    pub hiz_mips: u32,
    /// Where the cells lie: on the Earth, or flat.
    pub earth: TlmEarth,
}

/// One frame's TLM inputs as the GPU (and the twin) read them.
#[derive(Debug, Clone)]
pub struct TlmFrame {
    /// The frame's constants: matrix, frustum planes, LOD ranges and each ring's origin.
    pub uniforms: TlmUniforms,
    /// Columns then rows of every ring, camera-relative (`TlmLayout::spans`).
    pub spans: Vec<TlmSpan>,
}

impl TlmFrame {
    /// The frame's uniforms and spans, in f64 and rounded once; fails when the camera has no projection
    /// for the viewport or the dataset has more height levels than the pass supports.
    pub fn new(inputs: &TlmInputs) -> Result<Self, TlmError> {
        let (camera, layout, lods, s) = (inputs.camera, inputs.layout, inputs.lods, inputs.settings);
        let [width, height] = inputs.viewport_px;
        let clip: DMat4 = camera.clip_from_view(width, height)? * camera.view_from_world();
        let levels = lods.pyramid.levels;
        if levels > MAX_LEVELS || lods.range_m.len() > MAX_LEVELS as usize {
            return Err(TlmError::TooManyLevels(levels));
        }
        // Gribb & Hartmann, as `camera::Frustum` (no far plane: it is at infinity).
        let m = clip.transpose();
        let (x, y, z, w) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
        let planes = [w + x, w - x, w + y, w - y, w - z]
            .map(|p| (p / p.truncate().length().max(1e-300)).as_vec4().to_array());
        let mut u = TlmUniforms {
            clip_from_view_world: clip.as_mat4().to_cols_array_2d(),
            frustum_planes: planes,
            camera_z_m: inputs.camera_grid_m.z as f32,
            near_m: camera.near_m as f32,
            occlusion_tolerance_m: s.occlusion().m as f32,
            imagery_scale_sq: 0.0,
            radial_band_sq_m2: [0, 1, 2, 3]
                .map(|k| s.radial_bands_m.get(k).map_or(f32::INFINITY, |r| (r * r) as f32)),
            screen_px: [width, height],
            ndc_per_px: [(2.0 / f64::from(width)) as f32, (2.0 / f64::from(height)) as f32],
            hiz_mips: inputs.hiz_mips,
            imagery_levels: 0,
            height_lod_count: lods.range_m.len() as u32,
            rings: layout.rings,
            cells: layout.cells,
            corner_colours: s.corner_colours(),
            seed: s.seed,
            no_fuse: 0,
            occlusion_tolerance_per_m: s.occlusion().per_m() as f32,
            _pad: [0; 3],
            earth_bend: inputs.earth.bend.0,
            horizon: inputs.earth.horizon.map_or(HorizonCone::GPU_NONE, |h| h.gpu()),
            height_lod_range_m: [[0.0; 4]; MAX_LEVELS as usize / 4],
            height_levels: page_levels(&lods.pyramid),
            rings_info: [TlmRing::default(); TLM_MAX_RINGS as usize],
        };
        if let Some(imagery) = inputs.imagery {
            let scale = camera.metres_per_pixel(1.0, height) * imagery.lod_bias.exp2() / imagery.texel_m;
            u.imagery_scale_sq = (scale * scale) as f32;
            u.imagery_levels = imagery.levels;
        }
        for (m, range) in lods.range_m.iter().enumerate() {
            u.height_lod_range_m[m / 4][m % 4] = *range as f32;
        }
        for ring in 0..layout.rings {
            let origin = layout.origin_cell[ring as usize];
            u.rings_info[ring as usize] = TlmRing {
                // Beyond i32 the cells are far outside any dataset (culled); only ring 0 hashes it.
                origin_cell: origin.map(|g| g.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32),
                height_level: height_level(&lods.pyramid, lods.spacing_m, layout.ring_cell_m(ring)),
                _pad: 0,
            };
        }
        let spans = layout.spans(&lods.pyramid, lods.spacing_m, inputs.camera_grid_m);
        Ok(Self { uniforms: u, spans })
    }

    /// Cells the pass writes this frame: `cells`² per ring used.
    pub fn cell_count(&self) -> usize {
        (self.uniforms.rings * self.uniforms.cells * self.uniforms.cells) as usize
    }

    /// Bytes of the TLM buffer this frame fills (what the readback copies).
    pub fn output_bytes(&self) -> u64 {
        (self.cell_count() * size_of::<TlmCell>()) as u64
    }
}
