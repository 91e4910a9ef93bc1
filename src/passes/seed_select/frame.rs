//! Pass 3's CPU half: the cells a frame checks and its uniforms (`SeedFrame`, computed in f64 and
//! rounded once), and everything the pass writes, as CPU data (`SeedOutput`).

use glam::DVec3;

use crate::camera::{Camera, CameraError};
use crate::config::Settings;
use crate::dataset::Dataset;
use crate::earth::horizon::fall_per_m2;
use crate::gpu::gpu_types::{EarthNode, SeedBlock, SeedCell, SeedCounters, SeedRecord, SeedUniforms};
use crate::gpu::layout::{LCC_LEVELS, MAX_LEVELS};
use crate::seeds::wind::Wind;
use crate::seeds::{max_cells, workgroups_per_cell};
use crate::streaming::page_levels;

/// A ring-0 TLM cell whose seeds are wanted: its global address, pattern and radial LOD.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SeedCellRef {
    /// Global ring-0 address (x, y), in cells from grid space's origin: with a rank, a seed's identity.
    pub address: [i64; 2],
    /// The seed pattern the TLM hashed for it.
    pub pattern: u32,
    /// The TLM's radial band its nearest point lies in: the land-cover level its seeds read.
    pub radial_lod: u32,
}

/// What a frame's seed selection needs from the CPU.
pub struct SeedInputs<'a> {
    /// The `[seeds]`, `[tlm]` and `[draw_seeds]` settings the uniforms are taken from.
    pub settings: &'a Settings,
    /// The dataset whose height, land-cover and imagery grids the cells' corners are placed in.
    pub dataset: &'a Dataset,
    /// The frame's camera: its projection gives the frustum test and the near plane.
    pub camera: &'a Camera,
    /// Camera position in grid space, metres.
    pub camera_grid_m: DVec3,
    /// The depth target's size, pixels.
    pub viewport_px: [u32; 2],
    /// The TLM's visible ring-0 cells (`LoadMaps::seed_cells`), in any order, each with its
    /// mapping: its south-west corner's at height 0 (`PlacedView::node`; on the flat sheet the
    /// identity from that corner). They are checked near to far, and the farthest are dropped
    /// beyond `seeds::max_cells`.
    pub cells: &'a [(SeedCellRef, EarthNode)],
    /// Ranks worth checking (`SeedTables::active_ranks`).
    pub active_ranks: u32,
    /// The mapping of the grid point under the camera (`ExactPlacing::nadir_node`): the Earth's
    /// bend, which the occlusion march's segment sags by.
    pub nadir: EarthNode,
}

/// One frame's uniforms and cells: what the shader reads, and what the twin replays.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedFrame {
    /// The frame's constants, lengths pre-divided into each layer's texels.
    pub uniforms: SeedUniforms,
    /// The cells kept, near to far, each corner as integer texels and a remainder in every layer's
    /// grid.
    pub cells: Vec<SeedCell>,
    /// Cells beyond `seeds::max_cells` (the farthest) that were left out.
    pub cells_dropped: usize,
}

/// Everything pass 3 wrote in a frame, read back (or replayed by the twin).
#[derive(Debug, Clone, PartialEq)]
pub struct SeedOutput {
    /// The record buffer's filled part (`min(selected, capacity)` records), and each record's
    /// draw group (`seeds::seed_group`).
    pub records: Vec<SeedRecord>,
    /// Each record's draw group (species × `SEED_LODS` + radial LOD), parallel to `records`.
    pub keys: Vec<u32>,
    /// One entry per workgroup, cell by cell (`SeedFrame::blocks`).
    pub blocks: Vec<SeedBlock>,
    /// What the pass checked, culled (by reason), selected and dropped for want of room.
    pub counters: SeedCounters,
}

impl SeedOutput {
    /// The records block by block in table order: cell by cell, rank by rank, as the twin lists
    /// them, whatever order the blocks landed in.
    pub fn in_block_order(&self) -> Vec<SeedRecord> {
        self.blocks
            .iter()
            .flat_map(|b| &self.records[b.offset as usize..(b.offset + b.count) as usize])
            .copied()
            .collect()
    }
}

/// `cells` nearest first, by the distance from `camera_xy` to their centres (`cell_m` wide), ties
/// by address: pass 3's workgroups walk them in this order, its block table keeps it, and
/// compaction keeps the table's order within each draw, so every draw comes near to far and a
/// nearer crown's depth hides the fragments behind it before they are shaded. Deterministic, and
/// the cells dropped beyond `seeds::max_cells` are the farthest.
fn near_to_far(
    cells: &[(SeedCellRef, EarthNode)],
    camera_xy: [f64; 2],
    cell_m: f64,
) -> Vec<(SeedCellRef, EarthNode)> {
    let distance_sq = |c: &SeedCellRef| {
        let centre = c.address.map(|g| (g as f64 + 0.5) * cell_m);
        (centre[0] - camera_xy[0]).powi(2) + (centre[1] - camera_xy[1]).powi(2)
    };
    let mut sorted: Vec<(f64, &(SeedCellRef, EarthNode))> =
        cells.iter().map(|c| (distance_sq(&c.0), c)).collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.0.cmp(&b.1.0)));
    sorted.into_iter().map(|(_, c)| *c).collect()
}

/// `value` (≥ 0 or not) as an integer part and a remainder in [0, 1) that f32 can carry.
fn split(value: f64) -> (i32, f32) {
    let whole = value.floor();
    let frac = (value - whole) as f32;
    // A remainder a hair below 1 rounds to 1.0 in f32: carry it.
    if frac >= 1.0 { (whole as i32 + 1, 0.0) } else { (whole as i32, frac) }
}

impl SeedFrame {
    /// The frame's uniforms and cells from the camera, settings and TLM cells, in f64 and rounded once;
    /// fails when the camera has no projection for the viewport.
    pub fn new(inputs: &SeedInputs) -> Result<Self, CameraError> {
        let (s, dataset, camera) = (inputs.settings, inputs.dataset, inputs.camera);
        let [width, height] = inputs.viewport_px;
        let clip = camera.clip_from_view(width, height)? * camera.view_from_world();
        let rows = clip.transpose();
        // A side plane is `w ∓ x ≥ 0`: a sphere reaches it within `r · |row_w ∓ row_x|` (xyz).
        let row_len = |r: glam::DVec4| {
            let (plus, minus) = ((rows.w_axis + r).truncate(), (rows.w_axis - r).truncate());
            plus.length().max(minus.length()) as f32
        };
        let manifest = &dataset.manifest;
        let spacing_m = manifest.height.spacing_m;
        let half_spacing = 0.5 * spacing_m;
        let cell_m = s.tlm.cell_m;
        let seeds = &s.seeds;
        let mut u = SeedUniforms {
            clip_from_view_world: clip.as_mat4().to_cols_array_2d(),
            camera_z_m: inputs.camera_grid_m.z as f32,
            near_m: camera.near_m as f32,
            frustum_epsilon: seeds.frustum_epsilon as f32,
            no_fuse: 0,
            clip_row_len: [row_len(rows.x_axis), row_len(rows.y_axis)],
            screen_px: [width, height],
            occlusion_tolerance_m: seeds.occlusion().m as f32,
            occlusion_tolerance_per_m: seeds.occlusion().per_m() as f32,
            inv_reference_height_m: (1.0 / seeds.reference_height_m) as f32,
            sink_fraction: seeds.sink_fraction as f32,
            draw_reach_m: s.draw_seeds.reach_m.map(|r| r as f32),
            cell_in_samples: (cell_m / spacing_m) as f32,
            cell_in_lcc_texels: 0.0,
            cell_in_imagery_texels: 0.0,
            ground_radius_texels: 0.0,
            inv_spacing_m: (1.0 / spacing_m) as f32,
            seeds_per_pattern: seeds.seeds_per_pattern,
            capacity: seeds.capacity,
            seed: s.tlm.seed,
            height_size: dataset.height.pyramid.size,
            height_level_count: dataset.height.pyramid.levels.min(MAX_LEVELS),
            lcc_sub_bits: 0,
            lcc_size: [0; 2],
            imagery_level_count: 0,
            cell_m: cell_m as f32,
            imagery_size: [0; 2],
            ndc_per_px: [(2.0 / f64::from(width)) as f32, (2.0 / f64::from(height)) as f32],
            camera_sample: [0; 2],
            camera_sample_frac: [0.0; 2],
            refine_max_steps: seeds.occlusion_refine_steps,
            active_ranks: inputs.active_ranks.min(seeds.seeds_per_pattern),
            wind_reach_per_height: Wind::new(&s.wind).reach_per_height() as f32,
            cell_count: 0,
            height_levels: page_levels(&dataset.height.pyramid),
            lcc_levels: [[0; 4]; 4],
            imagery_levels: [[0; 4]; MAX_LEVELS as usize],
            vegetation: [0.0; 4],
            class_edge_dither: u32::from(seeds.class_edge_dither),
            chord_sag_per_m2: fall_per_m2(&inputs.nadir) as f32,
            _pad: [0; 2],
        };
        // Level-1 land-cover texels are twice the level-0 ones (the level that duplicates them).
        let lcc_texel_m = match (&dataset.landcover, &manifest.landcover) {
            (Some(layer), Some(meta)) => {
                let texel_m = 2.0 * meta.layer.texel_m;
                u.cell_in_lcc_texels = (cell_m / texel_m) as f32;
                u.lcc_sub_bits = meta.coding.sub_bits();
                u.lcc_size = layer.pyramid.size_at(1);
                u.lcc_levels = page_levels(&layer.pyramid);
                Some(texel_m)
            }
            _ => None,
        };
        let imagery_texel_m = match (&dataset.imagery, &manifest.imagery) {
            (Some(layer), Some(meta)) => {
                u.cell_in_imagery_texels = (cell_m / meta.texel_m) as f32;
                u.ground_radius_texels = (seeds.ground_colour_radius_m / meta.texel_m) as f32;
                u.imagery_level_count = layer.pyramid.levels.min(MAX_LEVELS);
                u.imagery_size = layer.pyramid.size;
                u.imagery_levels = page_levels(&layer.pyramid);
                if manifest.vegetation.is_some() {
                    let [bare, inv_span] = seeds.vegetation_ramp();
                    u.vegetation = [1.0, bare, inv_span, 0.0];
                }
                Some(meta.texel_m)
            }
            _ => None,
        };
        let camera_xy = [inputs.camera_grid_m.x, inputs.camera_grid_m.y];
        let (cx, cy) = (split(camera_xy[0] / spacing_m), split(camera_xy[1] / spacing_m));
        (u.camera_sample, u.camera_sample_frac) = ([cx.0, cy.0], [cx.1, cy.1]);
        let kept = inputs.cells.len().min(max_cells(u.active_ranks) as usize);
        let cells = near_to_far(inputs.cells, camera_xy, cell_m)[..kept]
            .iter()
            .map(|(c, earth)| {
                let corner = c.address.map(|g| g as f64 * cell_m);
                let in_grid = |texel_m: f64, offset_m: f64| {
                    let (x, y) =
                        (split((corner[0] + offset_m) / texel_m), split((corner[1] + offset_m) / texel_m));
                    ([x.0, y.0], [x.1, y.1])
                };
                let (height_sample, height_frac) = in_grid(spacing_m, 0.0);
                let (lcc_texel, lcc_frac) =
                    lcc_texel_m.map_or(([0; 2], [0.0; 2]), |t| in_grid(t, half_spacing));
                let (imagery_texel, imagery_frac) =
                    imagery_texel_m.map_or(([0; 2], [0.0; 2]), |t| in_grid(t, half_spacing));
                SeedCell {
                    rel_m: [(corner[0] - camera_xy[0]) as f32, (corner[1] - camera_xy[1]) as f32],
                    address: c.address.map(|g| g.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32),
                    height_sample,
                    height_frac,
                    lcc_texel,
                    lcc_frac,
                    imagery_texel,
                    imagery_frac,
                    pattern: c.pattern,
                    lcc_level: c.radial_lod.min(LCC_LEVELS - 1),
                    _pad: [0; 2],
                    earth: *earth,
                }
            })
            .collect::<Vec<_>>();
        u.cell_count = cells.len() as u32;
        Ok(Self { uniforms: u, cells, cells_dropped: inputs.cells.len() - kept })
    }

    /// Seeds this frame checks.
    pub fn checked(&self) -> u64 {
        self.cells.len() as u64 * u64::from(self.uniforms.active_ranks)
    }

    /// Entries of the block table this frame writes: one per workgroup, cell by cell.
    pub fn blocks(&self) -> u32 {
        self.cells.len() as u32 * workgroups_per_cell(self.uniforms.active_ranks)
    }
}
