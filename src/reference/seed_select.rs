//! How it works: the CPU twin of `shaders/seed_select.wgsl`, function for function. It reads what
//! the GPU pass reads — the frame's uniforms and cells, the patterns, the species tables, each
//! cache's page table with the texels of its resident slots, and the terrain depth — and decides
//! every seed with the same f32 arithmetic in the same order (products are plain `a * b`: Rust
//! never fuses them unasked). It returns the kept records in a canonical order (cell by cell,
//! rank by rank) and the same counters, and (`seed_select_blocks`) the block table the GPU writes,
//! as if every workgroup's block had landed in order: the GPU's blocks land in a varying order,
//! but read in table order (`SeedOutput::in_block_order`) its records equal the twin's list; when
//! the records overflow, the GPU settles its table to exactly the twin's, records in place.

use std::collections::HashMap;

use glam::Vec3;

use crate::classes::MAX_SPECIES_PER_CLASS;
use crate::dataset::{Dataset, PackError, TileId};
use crate::earth::local::NodeMapping;
use crate::gpu::gpu_types::{SeedBlock, SeedCell, SeedCounters, SeedRecord, SeedUniforms};
use crate::gpu::layout::{
    CLASS_EDGE_SALT, COUNT_CHECKED, COUNT_CLASS, COUNT_DISTANCE, COUNT_FRUSTUM, COUNT_OCCLUSION,
    COUNT_OVERFLOW, COUNT_RULE, COUNT_SELECTED, LCC_LEVELS, LCC_PACKED_LEVEL, LCC_SOURCE_LEVEL,
    LCC_TILE_TEXELS, OCCLUSION_FOOTPRINT_PX, SEED_COUNTERS, SEED_LODS, SEED_WORKGROUP, SpeciesLod, page_slot,
    seed_group,
};
use crate::passes::seed_select::frame::{SeedFrame, SeedOutput};
use crate::passes::seed_select::march::{block_max_m, height_tile_max_m};
use crate::seeds::{SeedTables, pcg, seed_hash, seed_variant, unit};
use crate::streaming::TileCache;

mod compare;
mod ground;
mod imagery;

use ground::ground_at;
use imagery::{ground_colour, vegetation_grows};

pub use compare::SeedComparison;
pub use ground::{OcclusionMarch, occlusion_march};

/// One cache as the shader sees it: the page table, and the texels (mip 0, border included) of
/// each resident slot.
#[derive(Debug, Clone, Default)]
pub struct TwinCache<T> {
    /// The page table as last uploaded: per tile of the pyramid, `page_entry(slot)`, or `PAGE_EMPTY`.
    pub page_table: Vec<u32>,
    /// Edge of a slot's mip 0, texels.
    pub extent: u32,
    /// Each resident slot's mip-0 texels, row-major, border included.
    pub slots: HashMap<u32, Vec<T>>,
}

impl<T: Copy> TwinCache<T> {
    /// A snapshot of `cache`, the texels of each resident tile from `texels` (mip 0 first).
    pub fn of(
        cache: &TileCache,
        mut texels: impl FnMut(TileId) -> Result<Vec<T>, PackError>,
    ) -> Result<Self, PackError> {
        let mut slots = HashMap::new();
        for (id, slot) in cache.resident_tiles() {
            slots.insert(slot, texels(id)?);
        }
        Ok(Self {
            page_table: cache.page_table_entries().to_vec(),
            extent: cache.pyramid().tile_extent(),
            slots,
        })
    }

    fn load(&self, slot: u32, x: u32, y: u32) -> T {
        // The GPU's out-of-range loads are undefined; the shader never makes one, nor may the twin.
        self.slots[&slot][(y * self.extent + x) as usize]
    }
}

/// Everything pass 3 reads, on the CPU.
pub struct SeedTwinInputs<'a> {
    /// The frame's uniforms and cells, as uploaded.
    pub frame: &'a SeedFrame,
    /// Every pattern's seed positions in its cell, unit square, pattern by pattern and rank by rank.
    pub patterns_unit: &'a [[f32; 2]],
    /// The class and species tables, as uploaded.
    pub tables: &'a SeedTables,
    /// The height cache: samples in metres.
    pub heights: &'a TwinCache<f32>,
    /// Per height tile, the highest ground drawn over it (`march::height_tile_max_m`).
    pub height_tile_max_m: &'a [f32],
    /// Per resident height slot, its tile's block tops (`march::block_max_m`).
    pub height_block_max_m: &'a HashMap<u32, Vec<f32>>,
    /// The land-cover cache: packed class words, as stored.
    pub landcover: &'a TwinCache<u32>,
    /// Imagery texels as stored: RGBA8, sRGB-encoded.
    pub imagery: &'a TwinCache<[u8; 4]>,
    /// Terrain depth (reversed-Z), top row first.
    pub depth: &'a [f32],
}

/// Everything pass 3 read in one frame, owned: what `Renderer::seed_snapshot` captures.
pub struct SeedSnapshot {
    /// The frame's uniforms and cells.
    pub frame: SeedFrame,
    /// Every pattern's seed positions in its cell, unit square.
    pub patterns_unit: Vec<[f32; 2]>,
    /// The class and species tables.
    pub tables: SeedTables,
    /// The three caches, as resident that frame.
    pub caches: TwinCaches,
    /// Terrain depth (reversed-Z), top row first.
    pub depth: Vec<f32>,
}

impl SeedSnapshot {
    /// The snapshot as the twin's inputs, borrowed.
    pub fn inputs(&self) -> SeedTwinInputs<'_> {
        SeedTwinInputs {
            frame: &self.frame,
            patterns_unit: &self.patterns_unit,
            tables: &self.tables,
            heights: &self.caches.heights,
            height_tile_max_m: &self.caches.height_tile_max_m,
            height_block_max_m: &self.caches.height_block_max_m,
            landcover: &self.caches.landcover,
            imagery: &self.caches.imagery,
            depth: &self.depth,
        }
    }
}

/// Snapshots of the three caches pass 3 reads.
pub struct TwinCaches {
    /// Height samples, metres.
    pub heights: TwinCache<f32>,
    /// Per height tile, the highest ground drawn over it (`march::height_tile_max_m`), and per
    /// resident slot its tile's block tops (`march::block_max_m`): where the occlusion march may
    /// leap. All +∞, it visits every sample.
    pub height_tile_max_m: Vec<f32>,
    /// See `height_tile_max_m`.
    pub height_block_max_m: HashMap<u32, Vec<f32>>,
    /// Land-cover class words, as stored.
    pub landcover: TwinCache<u32>,
    /// Imagery texels: RGBA8, sRGB-encoded.
    pub imagery: TwinCache<[u8; 4]>,
}

/// Builds the three cache snapshots of a renderer's caches over `dataset`.
pub fn snapshot_caches(
    dataset: &Dataset,
    heights: &TileCache,
    landcover: &TileCache,
    imagery: &TileCache,
) -> Result<TwinCaches, PackError> {
    let heights = TwinCache::of(heights, |id| dataset.height_tile(id))?;
    let landcover = TwinCache::of(landcover, |id| dataset.landcover_words(id))?;
    let extent = imagery.pyramid().tile_extent() as usize;
    let imagery = match &dataset.imagery {
        // Mip 0's texels as the GPU samples them: decoded from blocks by the format's rules.
        Some(layer) => TwinCache::of(imagery, |id| {
            let bytes = layer.tile_texels(id)?;
            Ok(bytes[..extent * extent * 4].chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
        })?,
        None => TwinCache {
            page_table: imagery.page_table_entries().to_vec(),
            extent: extent as u32,
            ..Default::default()
        },
    };
    let height_block_max_m =
        heights.slots.iter().map(|(&slot, samples)| (slot, block_max_m(samples))).collect();
    Ok(TwinCaches {
        heights,
        height_tile_max_m: height_tile_max_m(dataset),
        height_block_max_m,
        landcover,
        imagery,
    })
}

/// The seeds pass 3 keeps, cell by cell and rank by rank, and its counters (with overflow as the
/// GPU counts it when records beyond `capacity` are dropped). All kept seeds are returned, those
/// beyond `capacity` included.
pub fn seed_select(inputs: &SeedTwinInputs) -> (Vec<SeedRecord>, SeedCounters) {
    select_all(inputs, |_| {})
}

/// Pass 3's whole output as the GPU writes it when its blocks land in table order: the records
/// that fit `capacity` with their draw-group keys, the block table and the counters.
pub fn seed_select_blocks(inputs: &SeedTwinInputs) -> SeedOutput {
    let capacity = inputs.frame.uniforms.capacity;
    let mut blocks = Vec::new();
    let mut selected = 0u32;
    let (mut records, counters) = select_all(inputs, |kept| {
        let count = kept.min(capacity.saturating_sub(selected));
        blocks.push(SeedBlock { offset: if count == 0 { 0 } else { selected }, count });
        selected += kept;
    });
    records.truncate(capacity as usize);
    let keys = records
        .iter()
        .map(|r| {
            let SpeciesLod { species, lod, .. } = SpeciesLod::unpack(r.species_lod);
            seed_group(species, lod)
        })
        .collect();
    SeedOutput { records, keys, blocks, counters }
}

/// Every seed of every cell, workgroup by workgroup, calling `block` with each workgroup's
/// survivor count.
fn select_all(inputs: &SeedTwinInputs, mut block: impl FnMut(u32)) -> (Vec<SeedRecord>, SeedCounters) {
    let u = &inputs.frame.uniforms;
    let mut counts = [0u32; SEED_COUNTERS as usize];
    let mut records = Vec::new();
    for cell in &inputs.frame.cells {
        for first_rank in (0..u.active_ranks).step_by(SEED_WORKGROUP as usize) {
            let first = records.len();
            for rank in first_rank..u.active_ranks.min(first_rank + SEED_WORKGROUP) {
                counts[COUNT_CHECKED as usize] += 1;
                match select_seed(inputs, cell, rank) {
                    Ok(record) => {
                        counts[COUNT_SELECTED as usize] += 1;
                        records.push(record);
                    }
                    Err(count) => counts[count as usize] += 1,
                }
            }
            block((records.len() - first) as u32);
        }
    }
    let kept = records.len().min(u.capacity as usize);
    counts[COUNT_OVERFLOW as usize] = (records.len() - kept) as u32;
    let counters: SeedCounters = bytemuck::cast(counts);
    (records, counters)
}

struct GridPos {
    texel: [i32; 2],
    frac: [f32; 2],
}

fn grid_pos(corner: [i32; 2], corner_frac: [f32; 2], pos_unit: [f32; 2], cell_in_texels: f32) -> GridPos {
    let t = [corner_frac[0] + pos_unit[0] * cell_in_texels, corner_frac[1] + pos_unit[1] * cell_in_texels];
    let whole = t.map(f32::floor);
    GridPos {
        texel: [corner[0] + whole[0] as i32, corner[1] + whole[1] as i32],
        frac: [t[0] - whole[0], t[1] - whole[1]],
    }
}

fn to_clip(u: &SeedUniforms, p: [f32; 3]) -> [f32; 4] {
    let m = &u.clip_from_view_world;
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

fn class_at(u: &SeedUniforms, landcover: &TwinCache<u32>, q: [u32; 2], wanted: u32) -> Option<(u32, u32)> {
    (0..LCC_LEVELS).find_map(|n| {
        let level = (wanted + n) % LCC_LEVELS;
        let texel = match level {
            LCC_SOURCE_LEVEL => q,
            LCC_PACKED_LEVEL => q.map(|v| v >> 1),
            _ => q.map(|v| v << 1),
        };
        let info = u.lcc_levels[level as usize];
        let tile =
            [(texel[0] / LCC_TILE_TEXELS).min(info[1] - 1), (texel[1] / LCC_TILE_TEXELS).min(info[2] - 1)];
        let slot = page_slot(landcover.page_table[(info[0] + tile[1] * info[1] + tile[0]) as usize]);
        slot.map(|slot| {
            let word = landcover.load(
                slot,
                texel[0] - tile[0] * LCC_TILE_TEXELS,
                texel[1] - tile[1] * LCC_TILE_TEXELS,
            );
            if level != LCC_PACKED_LEVEL {
                return (word, level);
            }
            let shift = u.lcc_sub_bits * ((q[0] & 1) + 2 * (q[1] & 1));
            ((word >> shift) & ((1 << u.lcc_sub_bits) - 1), level)
        })
    })
}

/// How far a seed's land-cover read moves, texels, each way in [−0.5, 0.5): a class boundary
/// dithered (the shader's `class_offset`).
pub fn class_offset(address: [i32; 2], rank: u32, seed: u32) -> [f32; 2] {
    let h = pcg(seed_hash(address, rank, seed) ^ CLASS_EDGE_SALT);
    [unit(h) - 0.5, unit(pcg(h)) - 0.5]
}

/// Pixel column holding clip-space x at distance w: the shader's `pixel_of`.
fn pixel_of(x: f32, w: f32, n: u32, step: f32) -> u32 {
    let guess = ((x / w * 0.5 + 0.5) * n as f32).clamp(0.0, (n - 1) as f32);
    let mut i = guess as u32;
    for _ in 0..4 {
        if i > 0 && x < (i as f32 * step - 1.0) * w {
            i -= 1;
        } else if i + 1 < n && x >= ((i + 1) as f32 * step - 1.0) * w {
            i += 1;
        }
    }
    i
}

fn select_seed(inputs: &SeedTwinInputs, cell: &SeedCell, rank: u32) -> Result<SeedRecord, u32> {
    let u = &inputs.frame.uniforms;
    let pos_unit = inputs.patterns_unit[(cell.pattern * u.seeds_per_pattern + rank) as usize];
    let sample = grid_pos(cell.height_sample, cell.height_frac, pos_unit, u.cell_in_samples);
    let last = u.height_size.map(|n| n as i32 - 1);
    // Over the samples only, the last one included: the terrain mesh ends there.
    let beyond = |a: usize| sample.texel[a] > last[a] || (sample.texel[a] == last[a] && sample.frac[a] > 0.0);
    if sample.texel.iter().any(|&v| v < 0) || beyond(0) || beyond(1) || u.lcc_sub_bits == 0 {
        return Err(COUNT_CLASS);
    }
    let lcc = grid_pos(cell.lcc_texel, cell.lcc_frac, pos_unit, u.cell_in_lcc_texels);
    let offset = class_offset(cell.address, rank, u.seed);
    let step: [i32; 2] = match u.class_edge_dither {
        0 => [0, 0],
        _ => std::array::from_fn(|a| (lcc.frac[a] + offset[a]).floor() as i32),
    };
    let clamped = |a: usize, t: i32| t.clamp(0, u.lcc_size[a] as i32 - 1) as u32;
    if step != [0, 0] {
        let own = std::array::from_fn(|a| clamped(a, lcc.texel[a]));
        let (own, _) = class_at(u, inputs.landcover, own, cell.lcc_level).ok_or(COUNT_CLASS)?;
        let grows = inputs.tables.classes.get(own as usize).is_some_and(|c| c.rank_limit[0] > 0.0);
        if !grows {
            return Err(COUNT_CLASS);
        }
    }
    let q: [u32; 2] = std::array::from_fn(|a| clamped(a, lcc.texel[a] + step[a]));
    let (index, lcc_level) = class_at(u, inputs.landcover, q, cell.lcc_level).ok_or(COUNT_CLASS)?;
    let seeds = inputs.tables.classes.get(index as usize).ok_or(COUNT_CLASS)?;
    let k = (0..MAX_SPECIES_PER_CLASS).find(|&k| (rank as f32) < seeds.rank_limit[k]).ok_or(COUNT_CLASS)?;
    let species_index = seeds.species[k];
    let species = &inputs.tables.species[species_index as usize];

    let ground = ground_at(u, inputs.heights, &sample).ok_or(COUNT_RULE)?;
    let slope_sq = ground.gradient[0] * ground.gradient[0] + ground.gradient[1] * ground.gradient[1];
    if ground.height_m < species.altitude_m[0]
        || ground.height_m > species.altitude_m[1]
        || slope_sq > species.max_slope_tan_sq
    {
        return Err(COUNT_RULE);
    }

    let hash = seed_hash(cell.address, rank, u.seed);
    let imagery = grid_pos(cell.imagery_texel, cell.imagery_frac, pos_unit, u.cell_in_imagery_texels);
    if u.vegetation[0] != 0.0 && !vegetation_grows(u, inputs.imagery, &imagery, hash) {
        return Err(COUNT_RULE);
    }
    let height_m = species.height_m[0] + (species.height_m[1] - species.height_m[0]) * unit(hash);
    let in_cell = [pos_unit[0] * u.cell_m, pos_unit[1] * u.cell_m];
    let rel_xy = [cell.rel_m[0] + in_cell[0], cell.rel_m[1] + in_cell[1]];
    let earth = NodeMapping::from(&cell.earth);
    let foot = earth.position_m(Vec3::new(in_cell[0], in_cell[1], ground.height_m));

    let distance_sq = foot.x * foot.x + foot.y * foot.y + foot.z * foot.z;
    let size_scale = (height_m * u.inv_reference_height_m).min(1.0);
    let lods = seeds.lods.min(SEED_LODS);
    let lod = (0..lods)
        .find(|&lod| {
            let reach = u.draw_reach_m[lod as usize] * size_scale;
            distance_sq < reach * reach
        })
        .ok_or(COUNT_DISTANCE)?;

    let sink_m = height_m * u.sink_fraction;
    let up = earth.d_h + earth.d_xh * in_cell[0] + earth.d_yh * in_cell[1];
    let base = foot - up * sink_m;
    let sway_m = height_m * (species.wind_bend * u.wind_reach_per_height);
    let radius_m = height_m * species.radius_per_height + sway_m;
    let centre = to_clip(u, (base + up * (height_m * 0.5)).to_array());
    if centre[3] < -radius_m {
        return Err(COUNT_FRUSTUM);
    }
    let grown = (1.0 + u.frustum_epsilon) * centre[3];
    if centre[0].abs() > grown + radius_m * u.clip_row_len[0]
        || centre[1].abs() > grown + radius_m * u.clip_row_len[1]
    {
        return Err(COUNT_FRUSTUM);
    }

    let summit = to_clip(u, (base + up * height_m + up * sway_m).to_array());
    if summit[3] > u.near_m {
        let px = pixel_of(summit[0], summit[3], u.screen_px[0], u.ndc_per_px[0]);
        let py = pixel_of(-summit[1], summit[3], u.screen_px[1], u.ndc_per_px[1]);
        let reach = OCCLUSION_FOOTPRINT_PX;
        let (mut farthest, mut nearest) = (1.0f32, 0.0f32);
        let depth_at = |x: i32, y: i32| {
            let x = x.clamp(0, u.screen_px[0] as i32 - 1) as u32;
            let y = y.clamp(0, u.screen_px[1] as i32 - 1) as u32;
            inputs.depth[(y * u.screen_px[0] + x) as usize]
        };
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let d = depth_at(px as i32 + dx, py as i32 + dy);
                farthest = farthest.min(d);
                nearest = nearest.max(d);
            }
        }
        let tolerance_m = u.occlusion_tolerance_m + u.occlusion_tolerance_per_m * summit[3] + sway_m;
        let behind_m = summit[3] - tolerance_m;
        let mut hidden = behind_m * farthest > u.near_m;
        if !hidden && behind_m * nearest > u.near_m {
            hidden = if u.refine_max_steps == 0 {
                behind_m * depth_at(px as i32, py as i32) > u.near_m
            } else {
                let summit_rel_z = ground.height_m - u.camera_z_m - sink_m + height_m + sway_m;
                occlusion_march(inputs, [rel_xy[0], rel_xy[1], summit_rel_z]).hidden
            };
        }
        if hidden {
            return Err(COUNT_OCCLUSION);
        }
    }

    let drawn = species_index + seed_variant(hash, species.variants);
    Ok(SeedRecord {
        position_rel_m: base.to_array(),
        height_m,
        address: cell.address,
        rank,
        species_lod: SpeciesLod {
            species: drawn,
            lod,
            last: u32::from(lod + 1 == lods),
            lcc_level,
            height_level: ground.level,
        }
        .pack(),
        jitter: pcg(hash),
        ground_colour: ground_colour(u, inputs.imagery, &imagery, hash),
        radius_m,
        ground_m: ground.height_m,
    })
}
