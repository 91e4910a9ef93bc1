//! How it works: every constant and bit layout the CPU and the shaders share, defined once (the
//! role `config.h` plays in niagara). `wgsl_constant!` defines a Rust constant and lists it for the
//! generated WGSL prelude (`gpu::shaders::prelude`); `packed_word!` defines a bit-packed u32 word
//! as a Rust struct with `pack`/`unpack` and emits the same struct and functions in WGSL, so a
//! shift or a mask is never written by hand on either side. This module imports nothing of the
//! crate: anything may depend on it, and it on nothing.
//!
//! To add a constant the shaders see: add it to one of the `wgsl_constants!` blocks below (the
//! atmosphere's are in `layout/atmosphere.rs`, included here). That is the only place to touch;
//! the shader then names it. The two macros and the types they describe
//! words with live in `words.rs`, which imports nothing of the crate either.

#[macro_use]
mod words;

pub use words::{BitField, PackedWord, WgslLiteral, mask};

// --- The dataset's tiles (on disk and in the caches) ---
wgsl_constants! { dataset_constants:
    /// Height tiles: 256 cells (257 shared-edge samples) plus a 1-sample border for normals.
    pub const HEIGHT_TILE_CELLS: u32 = 256;
    /// Samples of border on each side of a height tile: normals are central differences at its edges too.
    pub const HEIGHT_BORDER: u32 = 1;
    /// Samples along a stored height tile's edge, borders included.
    pub const HEIGHT_TILE_EXTENT: u32 = HEIGHT_TILE_CELLS + 1 + 2 * HEIGHT_BORDER;
    /// Cells along a height block, whose top pass 3's occlusion march leaps by (`seed_select::march`).
    pub const HEIGHT_BLOCK_CELLS: u32 = 16;
    /// Blocks along a height tile's edge.
    pub const HEIGHT_TILE_BLOCKS: u32 = HEIGHT_TILE_CELLS / HEIGHT_BLOCK_CELLS;
    /// Levels down to which a tile's block lies in one tile of each finer level: log2 of the above.
    pub const HEIGHT_BLOCK_LEVELS: u32 = HEIGHT_TILE_BLOCKS.trailing_zeros();
    /// Imagery and land-cover tiles: 512 texels.
    pub const CELL_TILE_TEXELS: u32 = 512;
    /// Imagery carries an 8-texel border, enough for trilinear and anisotropic filtering down its
    /// 4 stored mips (8, 4, 2, 1 texels of border).
    pub const IMAGERY_BORDER: u32 = 8;
    /// Mips stored per imagery tile, mip 0 included.
    pub const IMAGERY_MIPS: u32 = 4;
    /// Texels along a stored imagery tile's edge (mip 0), borders included.
    pub const IMAGERY_TILE_EXTENT: u32 = CELL_TILE_TEXELS + 2 * IMAGERY_BORDER;
    /// Texels along an imagery tile's edge, borders excluded: the ground one tile covers.
    pub const IMAGERY_TILE_TEXELS: u32 = CELL_TILE_TEXELS;
    /// Land cover is read texel by texel (nearest), so it needs no border.
    pub const LANDCOVER_BORDER: u32 = 0;
    /// Texels along a land-cover tile's edge (there is no border).
    pub const LCC_TILE_TEXELS: u32 = CELL_TILE_TEXELS;
    /// Levels of the LCC quadtree (paper § 4.1): 0 duplicates each source texel onto its four
    /// children, 1 is the source, 2 packs four level-1 classes into sub-codes.
    pub const LCC_LEVELS: u32 = 3;
    /// The level that stores the source's classes one per texel.
    pub const LCC_SOURCE_LEVEL: u32 = 1;
    /// The level that packs four neighbouring level-1 classes into one word.
    pub const LCC_PACKED_LEVEL: u32 = 2;
    /// Levels a page table describes at most (a 2^15-tile-wide layer).
    pub const MAX_LEVELS: u32 = 16;
    /// A page-table entry of a tile that is not resident; otherwise the entry is its slot + 1
    /// (`PageEntry`).
    pub const PAGE_EMPTY: u32 = 0;
    /// `TerrainUniforms::imagery_texels`: the dataset has no imagery (the relief tint shows).
    pub const IMAGERY_NONE: u32 = 0;
    /// Imagery texels hold their colour as it is, alpha the coverage (RGBA8, BC7: a texel
    /// without data keeps a colour, the valid texels' mean).
    pub const IMAGERY_STRAIGHT: u32 = 1;
    /// Imagery texels without data are transparent black (BC1's punch-through): a filtered texel
    /// is the covered texels' colour times their coverage, so the shader divides by alpha.
    pub const IMAGERY_PUNCHED: u32 = 2;
    /// Imagery texels hold their colour as it is, alpha the coverage and the vegetation index
    /// (`dataset::vegetation`: 0 no data, else 1 + the index coded).
    pub const IMAGERY_VEGETATION: u32 = 3;
}

/// A page-table entry: the tile's cache slot (texture-array layer) + 1, or `PAGE_EMPTY`.
pub const fn page_entry(slot: u32) -> u32 {
    slot + 1
}

/// The cache slot of a page-table entry, `None` for `PAGE_EMPTY`.
pub const fn page_slot(entry: u32) -> Option<u32> {
    if entry == PAGE_EMPTY { None } else { Some(entry - 1) }
}

// --- Pass 1, the Tile Load Map ---
wgsl_constants! { tlm_constants:
    /// Workgroup edge of the TLM dispatch.
    pub const TLM_WORKGROUP: u32 = 8;
    /// Rings the uniforms have room for (`tlm.max_rings` is at most this).
    pub const TLM_MAX_RINGS: u32 = 16;
    /// `TlmSpan::flags`: the column (row) overlaps the dataset.
    pub const TLM_SPAN_INSIDE: u32 = 1;
    /// `TlmSpan::flags`: the column (row) lies within the inner ring's; a cell whose column and row
    /// both do is covered by the inner ring.
    pub const TLM_SPAN_COVERED: u32 = 2;
    /// Distance bands of a ring-0 cell (`tlm.radial_bands_m`): its radial LOD is the first band
    /// its nearest point lies in, the land-cover level its seeds read.
    pub const TLM_RADIAL_BANDS: u32 = 3;
    /// Radial LOD of a cell beyond every band, or culled: no seeds there.
    pub const RADIAL_INACTIVE: u32 = TLM_RADIAL_BANDS;
    /// `TlmCell::visibility` of a culled cell.
    pub const TLM_CULLED: u32 = 0;
    /// `TlmCell::visibility` of a visible cell is `TLM_FIRST_PATTERN + pattern` in ring 0 (and
    /// `TLM_FIRST_PATTERN` in outer rings, which show no seeds).
    pub const TLM_FIRST_PATTERN: u32 = 1;
}

/// `TlmCell::visibility` of a visible ring-0 cell showing seed pattern `pattern`.
pub const fn tlm_visibility(pattern: u32) -> u32 {
    TLM_FIRST_PATTERN + pattern
}

/// The seed pattern of a visible ring-0 cell, `None` for a culled one.
pub const fn tlm_pattern(visibility: u32) -> Option<u32> {
    if visibility == TLM_CULLED { None } else { Some(visibility - TLM_FIRST_PATTERN) }
}

packed_word! {
    /// A range of levels, finest first: `TlmCell::imagery_lod` (the imagery levels a cell's pixels
    /// need) and `TlmCell::height_lod` (the terrain LODs at its nearest and farthest points).
    pub struct LevelRange as level_range {
        /// The finest level: the one at the cell's nearest point.
        min: 8,
        /// The coarsest level: the one at the cell's farthest point.
        max: 8,
    }
}

packed_word! {
    /// `TlmSpan::height_tiles`: the first and last height tile a column (row) overlaps.
    pub struct TileSpan as tile_span {
        /// Index along x (y) of the first tile it overlaps, within its level.
        first: 16,
        /// Index along x (y) of the last tile it overlaps, inclusive.
        last: 16,
    }
}

// --- The depth pyramid ---
wgsl_constants! { hiz_constants:
    /// Workgroup edge of the reduction dispatches.
    pub const HIZ_WORKGROUP: u32 = 8;
}

// --- Pass 3, seed selection ---
wgsl_constants! { seed_constants:
    /// Workgroup size of the seed-selection dispatch.
    pub const SEED_WORKGROUP: u32 = 64;
    /// Words of a ballot: one bit per lane of a pass-3 workgroup (`shaders/shared/blocks.wgsl`).
    pub const BALLOT_WORDS: u32 = SEED_WORKGROUP / 32;
    /// Most species in one class table.
    pub const MAX_SPECIES: u32 = 16;
    /// Most seed rules (species) in one class.
    pub const MAX_SPECIES_PER_CLASS: u32 = 4;
    /// Draw LODs of a seed: 0 the real mesh, 1 to 3 its billboard clouds (17, 8 and 2 planes), out
    /// to the four `draw_seeds.reach_m`.
    pub const SEED_LODS: u32 = 4;
    /// Draw groups: one per (species, LOD), `species × SEED_LODS + lod` (`seed_group`).
    pub const SEED_GROUPS: u32 = MAX_SPECIES * SEED_LODS;
    /// Samples per pixel of pass 4's multisampled drawing (`draw_seeds.samples` = this, or 1 for
    /// the single-sampled alpha test): 4 is what every adapter supports for the colour and depth
    /// formats, and its standard sample positions are what `fs_coverage` spreads a pixel's
    /// coverage over.
    pub const SEED_SAMPLES: u32 = 4;
    /// Indirect draws compaction writes: each group's own, then (at `SEED_GROUPS + group`) the
    /// same instances with the next LOD's geometry, which the seeds in the outer band of their LOD
    /// cross-fade into.
    pub const SEED_DRAWS: u32 = 2 * SEED_GROUPS;
    /// Indices into `SeedCounters` (as an array of u32): where a seed's outcome is counted.
    pub const COUNT_SELECTED: u32 = 0;
    /// `SeedCounters::overflow`: selected, but the record buffer was full.
    pub const COUNT_OVERFLOW: u32 = 1;
    /// `SeedCounters::checked`: every seed pass 3 looked at.
    pub const COUNT_CHECKED: u32 = 2;
    /// `SeedCounters::class`: culled for its land-cover class (none, or none at its rank).
    pub const COUNT_CLASS: u32 = 3;
    /// `SeedCounters::rule`: culled by its species' altitude or slope rule.
    pub const COUNT_RULE: u32 = 4;
    /// `SeedCounters::distance`: beyond the radial LOD distance for its size.
    pub const COUNT_DISTANCE: u32 = 5;
    /// `SeedCounters::frustum`: its bounding sphere lies outside the view frustum.
    pub const COUNT_FRUSTUM: u32 = 6;
    /// `SeedCounters::occlusion`: its summit lies behind the terrain's depth.
    pub const COUNT_OCCLUSION: u32 = 7;
    /// Counters in `SeedCounters`: its length as an array of u32.
    pub const SEED_COUNTERS: u32 = 8;
    /// `SeedSpecies::kind` codes.
    pub const KIND_TREE: u32 = 0;
    /// `SeedSpecies::kind` of a bush.
    pub const KIND_BUSH: u32 = 1;
    /// `SeedSpecies::kind` of a rock.
    pub const KIND_ROCK: u32 = 2;
    /// Pixels around a summit's whose farthest terrain depth decides its occlusion (1: a 3 × 3
    /// block), so a summit within a pixel of a silhouette is kept.
    pub const OCCLUSION_FOOTPRINT_PX: i32 = 1;
    /// Imagery texels averaged into a seed's ground colour.
    pub const GROUND_SAMPLES: u32 = 4;
    /// Salt of the hash that thins a seed by the imagery's vegetation index (`seeds.vegetation_*`),
    /// apart from every other use of the seed's hash.
    pub const VEGETATION_SALT: u32 = 0x5eed_0e91;
    /// Salt of the hash that moves a seed's land-cover read by up to half a texel each way (a
    /// forest's edge dithered, `seed_select.wgsl` `class_offset`).
    pub const CLASS_EDGE_SALT: u32 = 0xed9e_5eed;
    /// A vegetation-coded imagery alpha (`dataset::vegetation`): 0 where the imagery has no data,
    /// else 1 + the index mapped from [−1, 1] onto 0 to this.
    pub const VEGETATION_CODE_STEPS: u32 = 254;
    /// Mixed into the seed hash so it never equals the pattern hash of the same cell.
    pub const SEED_SALT: u32 = 0x5eed_5eed;
    /// Mixed into a seed's hash to pick its species' variant, so the pick is independent of the
    /// height, turn and colour the same hash gives it.
    pub const SEED_VARIANT_SALT: u32 = 0x7a41_a7e5;
    /// A land-cover lookup that found no resident level.
    pub const NO_CLASS: u32 = u32::MAX;
}

const _: () = assert!(SEED_WORKGROUP.is_multiple_of(32), "ballots need whole words");

/// The draw group of a seed of species `species` at draw LOD `lod`: the key pass 3 writes beside
/// each record and compaction groups by.
pub const fn seed_group(species: u32, lod: u32) -> u32 {
    species * SEED_LODS + lod
}

packed_word! {
    /// `SeedRecord::species_lod`: what a seed is and which levels it was read from.
    pub struct SpeciesLod as species_lod {
        /// Index into the species table.
        species: 8,
        /// Draw LOD (0 the mesh, 1 to 3 the billboard clouds).
        lod: 3,
        /// 1 when `lod` is the last its class draws (`SeedClass::lods`): the seed fades out at
        /// its end instead of into the next LOD.
        last: 1,
        /// Land-cover level its class was read from.
        lcc_level: 4,
        /// Height level it was placed on.
        height_level: 16,
    }
}

packed_word! {
    /// `SeedRecord::jitter`: the hash bits that vary a seed.
    pub struct SeedJitter as seed_jitter {
        /// Turn about the vertical, in 1/65536 of a full turn.
        angle: 16,
        /// Colour variation, 0 to 65535 (half way: none).
        colour: 16,
    }
}

// --- Pass 4, compaction and drawing ---
wgsl_constants! { draw_constants:
    /// Blocks per chunk: the workgroup of `reduce` and `scatter`, one lane per block, whose
    /// block × group table of counts (`COMPACT_CHUNK × SEED_GROUPS` words) fits WebGPU's 16 KiB of
    /// workgroup memory.
    pub const COMPACT_CHUNK: u32 = 64;
    /// Invocations of the `scan` workgroup (one per group), each summing a run of chunks.
    pub const COMPACT_WORKGROUP: u32 = 256;
    /// `SeedMaterial::flags`: the material samples a layer of the seed texture array.
    pub const MATERIAL_TEXTURED: u32 = 1;
    /// `SeedMaterial::flags`: texture coordinates wrap (else they clamp).
    pub const MATERIAL_REPEAT: u32 = 2;
    /// `SeedMaterial::flags`: the material's quads are leaves that thin out as they shrink on
    /// screen (continuous LOD, `impostor::Detail::Leaves`).
    pub const MATERIAL_LEAVES: u32 = 4;
    /// `SeedMaterial::flags`: the material's stems are widened to a pixel on a share of the seeds
    /// as they shrink below it (continuous LOD, `impostor::Detail::Stems`).
    pub const MATERIAL_STEMS: u32 = 8;
    /// `SeedMaterial::flags`: bark (a trunk, a branch): it keeps its own colour where foliage takes
    /// on the ground's (`Species::ground_blend`; `impostor::Material::is_bark`).
    pub const MATERIAL_BARK: u32 = 16;
    /// `SeedMaterial::flags`: a slicing's slice (`draw_seeds.slicings`): drawn only in the two
    /// slicings nearest the view, dithered by their blend (`impostor::slicing::view_blend`).
    pub const MATERIAL_SLICE: u32 = 32;
    /// The slicings' blend dithers with the cross-fade's pattern transposed and its shift XORed
    /// with this, so the two dithers do not correlate (`draw_seeds.wgsl` `faded_out`, Rust
    /// `reference::slicing`).
    pub const SLICE_DITHER_SALT: u32 = 9;
    /// Continuous LOD: the projected size, pixels, below which leaves thin out; the kept ones
    /// grow back to it, so the crown keeps its area and no drawn leaf is smaller.
    pub const DETAIL_FULL_PX: f32 = 2.0;
    /// Continuous LOD: stems narrower than this on screen, pixels, are drawn this wide on a share
    /// of the seeds (their width over this).
    pub const DETAIL_MIN_PX: f32 = 1.0;
    /// Crown shading: the half width of a crown, per metre of the plant's height, over which its
    /// side towards the sun turns from shaded to lit.
    pub const CROWN_HALF_WIDTH_PER_HEIGHT: f32 = 0.3;
}

const _: () = assert!(SEED_GROUPS <= COMPACT_CHUNK, "a lane per group sums or scans a column");
const _: () = assert!(COMPACT_CHUNK * SEED_GROUPS * 4 <= 16384, "the chunk's table fits workgroup memory");

// --- Cloud shadows (`light`) ---
wgsl_constants! { cloud_constants:
    /// Octaves of the clouds' value noise, each twice the frequency and half the weight of the
    /// one before.
    pub const CLOUD_OCTAVES: u32 = 4;
    /// The noise lattice repeats every this many cells of the largest octave (a power of two): the
    /// CPU hands the camera's position modulo it, so f32 keeps centimetres anywhere on Earth.
    pub const CLOUD_PERIOD_CELLS: u32 = 256;
    /// Half the width of a cloud's edge, in noise units: the penumbra over which its shadow fades.
    pub const CLOUD_EDGE: f32 = 0.04;
    /// Salt of the clouds' lattice hash, apart from every seed hash.
    pub const CLOUD_SALT: u32 = 0x7c1d_5a0b;
}

// --- Light: how the ground and the foliage are lit (`light`, the colour follow-up) ---
wgsl_constants! { light_constants:
    /// Foliage's direct sun on its own facing (leaves, billboards, slices: normals that scatter),
    /// as a share of the sun on level ground from straight above...
    pub const FOLIAGE_SUN: f32 = 0.61;
    /// ... its sun through the crown by the sun's height alone (light wraps around leaves)...
    pub const FOLIAGE_SUN_WRAP: f32 = 0.39;
    /// ... and its sky light, as a share of the sky's on level ground.
    pub const FOLIAGE_SKY: f32 = 0.86;
    /// The follow-up's fades of detail (the texcells' by pixel size, `TEXCELL_DETAIL_*`, a seed's
    /// by its own size on screen, `SEED_DETAIL_*`) apply to views from above, which the
    /// photograph was taken from: none where the eye looks down at the forest less steeply than
    /// this (sine of the angle below the horizon, 20°), where the canopy's side and the ground it
    /// hides are what the photograph cannot show...
    pub const PHOTO_DETAIL_GRAZING_SIN: f32 = 0.342;
    /// ... all where it looks down more steeply than this (45°).
    pub const PHOTO_DETAIL_STEEP_SIN: f32 = 0.707;
    /// A seed keeps all its own detail (texture, shading, gaps' colours) where it stands at least
    /// this many pixels tall...
    pub const SEED_DETAIL_FULL_PX: f32 = 8.0;
    /// ... and shows only its mean colour seen from above (the photograph's under it, by its
    /// colour variation) where it stands at most this many: a crown of a pixel or two cannot show
    /// its shading, and one sample of it a pixel makes the pixel flicker as it moves.
    pub const SEED_DETAIL_NONE_PX: f32 = 2.0;
}

// --- The Earth (`earth`) ---
wgsl_constants! { earth_constants:
    /// Points per workgroup of the Earth mapping's probe (`earth::gpu::probe_positions`).
    pub const EARTH_PROBE_WORKGROUP: u32 = 64;
}

// --- The atmosphere (`atmosphere`, `passes::atmosphere`): its block, included ---
include!("layout/atmosphere.rs");

// --- Wind (`seeds::wind`) ---
wgsl_constants! { wind_constants:
    /// Share of a plant's mean lean that gusts take away between their crests (0: no gusts).
    pub const WIND_GUST_DEPTH: f32 = 0.4;
    /// A plant's own sway along the wind, as a share of its mean lean.
    pub const WIND_SWAY_OF_LEAN: f32 = 0.5;
    /// Its sway across the wind, as a share of its sway along it (an elliptical swing).
    pub const WIND_CROSS_OF_SWAY: f32 = 0.3;
    /// The frequency of the swing across the wind, as a multiple of the one along it.
    pub const WIND_CROSS_HZ_RATIO: f32 = 1.31;
    /// A plant 1 m tall sways at this frequency, Hz; one H metres tall at this / √H (at most this).
    pub const WIND_SWAY_HZ_AT_1M: f32 = 2.2;
    /// A leaf's flutter about its pivot, radians per unit of mean lean (0.36 rad at 10 m/s)...
    pub const WIND_FLUTTER_RAD_PER_LEAN: f32 = 9.0;
    /// ... and at most this, radians.
    pub const WIND_FLUTTER_MAX_RAD: f32 = 0.6;
    /// A leaf's flutter frequency, Hz, at the slowest; each leaf's lies up to half as much above.
    pub const WIND_FLUTTER_HZ: f32 = 2.0;
    /// The farthest a flutter moves a vertex, as a fraction of the plant's height (a bound that
    /// culling can rely on whatever the model's leaves).
    pub const WIND_FLUTTER_MAX_PER_HEIGHT: f32 = 0.02;
}

// --- Texcells ---
wgsl_constants! { texcell_constants:
    /// Most forest samples (dense classes with a baked sample) a renderer draws: the class
    /// table's sample indices and the texture array's layers are sized for them.
    pub const TEXCELL_MAX_SAMPLES: u32 = 4;
    /// Ground cells along each side of a forest sample (`texcell::tiling`): the 2 × 2 torus that
    /// holds each of the eight tiles once.
    pub const TEXCELL_REFERENCE_CELLS: u32 = 2;
    /// Most slices of a forest sample's finest level (2^N): the texture array holds this many
    /// layers per sample.
    pub const TEXCELL_MAX_SLICES: u32 = 64;
    /// The colour follow-up fades the forest's own detail out where a pixel grows past a crown
    /// (nc's broadleaves and pines are 5 to 10 m across): full where a pixel spans at most this
    /// many metres...
    pub const TEXCELL_DETAIL_FULL_PX_M: f32 = 4.0;
    /// ... none where it spans this many: a tree is then smaller than a pixel, and the forest
    /// shows the photograph's colour alone, which already holds what the trees look like there.
    pub const TEXCELL_DETAIL_NONE_PX_M: f32 = 8.0;
    /// Points per workgroup of the shader's probe of its tiling (`passes::texcells::gpu::probe`).
    pub const TEXCELL_PROBE_WORKGROUP: u32 = 64;
    /// `TexcellSlice::kind`: a regular slice of a patch drawn with regular slices only.
    pub const TEXCELL_REGULAR: u32 = 0;
    /// `TexcellSlice::kind`: a regular slice of a patch that silhouette texcells share (its
    /// fragments give way to them where the view grazes).
    pub const TEXCELL_REGULAR_SHARED: u32 = 1;
    /// `TexcellSlice::kind`: a patch's silhouette texcell, the slab's top face whose fragments
    /// march their ray through the 3D texture.
    pub const TEXCELL_SILHOUETTE: u32 = 2;
}

packed_word! {
    /// `TexcellRecord::slice`: which part of its terrain node a texcell instance covers and which
    /// of its slices it draws.
    pub struct TexcellSlice as texcell_slice {
        /// The node's quadrant (bit 0: east half, bit 1: north half), as the terrain's grid.
        quadrant: 2,
        /// The slice, 0 the lowest, of the `2^(N − level)` the patch draws.
        index: 8,
        /// The slice pyramid's level: the patch draws `S_level` (`2^(N − level)` slices, each
        /// aggregating `2^level` of the finest) and samples mips at or above `level`.
        level: 4,
        /// `TEXCELL_REGULAR`, `TEXCELL_REGULAR_SHARED` or `TEXCELL_SILHOUETTE`.
        kind: 2,
    }
}

/// The WGSL twins of the functions of this module, emitted into the prelude after the constants
/// (kept here, beside their Rust twins, so the two change together).
pub const WGSL_FUNCTIONS: &str = r"
// The texture-array layer of a resident tile's page-table entry (Rust: `page_slot`).
fn page_layer(entry: u32) -> i32 {
    return i32(entry - 1u);
}

// The visibility of a ring-0 cell showing seed pattern `pattern` (Rust: `tlm_visibility`).
fn tlm_visibility(pattern: u32) -> u32 {
    return TLM_FIRST_PATTERN + pattern;
}

// The vegetation index of a vegetation-coded imagery alpha in [0, 1], filtered or not (Rust:
// `vegetation_index`).
fn vegetation_index(alpha: f32) -> f32 {
    return (alpha * 255.0 - 1.0) / f32(VEGETATION_CODE_STEPS) * 2.0 - 1.0;
}

// The imagery's coverage from a vegetation-coded alpha: any code above 0 is data (Rust:
// `vegetation_coverage`).
fn vegetation_coverage(alpha: f32) -> f32 {
    return min(alpha * 255.0, 1.0);
}

// The draw group of a seed (Rust: `seed_group`).
fn seed_group(species: u32, lod: u32) -> u32 {
    return species * SEED_LODS + lod;
}
";

/// The vegetation index of a vegetation-coded imagery alpha in [0, 1] (WGSL: `vegetation_index`).
pub fn vegetation_index(alpha: f32) -> f32 {
    (alpha * 255.0 - 1.0) / VEGETATION_CODE_STEPS as f32 * 2.0 - 1.0
}

/// The imagery's coverage from a vegetation-coded alpha (WGSL: `vegetation_coverage`).
pub fn vegetation_coverage(alpha: f32) -> f32 {
    (alpha * 255.0).min(1.0)
}

/// Every constant the prelude declares: name, WGSL type, literal.
pub fn wgsl_constants() -> Vec<(&'static str, &'static str, String)> {
    [
        dataset_constants(),
        tlm_constants(),
        hiz_constants(),
        seed_constants(),
        draw_constants(),
        texcell_constants(),
        wind_constants(),
        cloud_constants(),
        light_constants(),
        earth_constants(),
        atmosphere_constants(),
    ]
    .concat()
}

/// Every packed word the prelude declares.
pub const PACKED_WORDS: &[PackedWord] =
    &[LevelRange::WORD, TileSpan::WORD, SpeciesLod::WORD, SeedJitter::WORD, TexcellSlice::WORD];

#[cfg(test)]
mod tests;
