//! The Tile Load Map's structs (pass 1): its cells, ring spans, rings and per-frame constants.

use bytemuck::{Pod, Zeroable};

use crate::gpu::layout::{MAX_LEVELS, TLM_MAX_RINGS};
use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// One cell of the Tile Load Map, as the TLM pass writes it. WGSL: `TlmCell` in
    /// `shaders/tile_load_map.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Hash, Default)]
    pub struct TlmCell {
        /// `TLM_CULLED` (outside the dataset, covered by an inner ring, outside the frustum,
        /// occluded); else `tlm_visibility(seed pattern)` in ring 0 and `TLM_FIRST_PATTERN` in
        /// outer rings (`layout::tlm_pattern` reads it).
        pub visibility: u32,
        /// Imagery levels the cell needs, a `layout::LevelRange` (0 without imagery).
        pub imagery_lod: u32,
        /// Terrain (CDLOD) LODs at the cell's nearest and farthest points, a `layout::LevelRange`.
        pub height_lod: u32,
        /// The land-cover level its seeds read: the first of the `TLM_RADIAL_BANDS` its nearest
        /// point lies in, `RADIAL_INACTIVE` beyond them all or when culled.
        pub radial_lod: u32,
    }
}

gpu_struct! {
    /// One column (or row) of one TLM ring: everything about a cell that depends on its x (or y)
    /// alone, computed in f64 on the CPU. WGSL: `TlmSpan` in `shaders/tile_load_map.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct TlmSpan {
        /// The column's extent clamped to the dataset, relative to the camera (lo, hi), metres.
        pub rel_m: [f32; 2],
        /// Height tiles it overlaps at its ring's height level, a `layout::TileSpan`.
        pub height_tiles: u32,
        /// `TLM_SPAN_INSIDE` (overlaps the dataset), `TLM_SPAN_COVERED` (inside the inner ring).
        pub flags: u32,
    }
}

gpu_struct! {
    /// Per TLM ring constants. WGSL: `TlmRing` in `shaders/tile_load_map.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct TlmRing {
        /// Global address (x, y) of the ring's south-west cell, in cells of the ring.
        pub origin_cell: [i32; 2],
        /// Height pyramid level whose tiles bound the heights of the ring's cells.
        pub height_level: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: u32,
    }
}

gpu_struct! {
    /// Per-frame constants of the TLM pass. WGSL: `TlmUniforms` in `shaders/tile_load_map.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
    pub struct TlmUniforms {
        /// Clip space from camera-relative world space (columns), as the terrain draws with.
        pub clip_from_view_world: [[f32; 4]; 4],
        /// Left, right, bottom, top and near planes (xyz · p + w ≥ 0 inside), camera-relative.
        pub frustum_planes: [[f32; 4]; 5],
        /// Camera height in grid space, metres.
        pub camera_z_m: f32,
        /// Near plane, metres: reversed-Z depth is `near_m / view distance`.
        pub near_m: f32,
        /// How far a box may lie behind the depth and still be visible, metres, before it grows with
        /// distance (`tlm.occlusion_tolerance_m`).
        pub occlusion_tolerance_m: f32,
        /// (metres per pixel at 1 m · 2^lod_bias / level-0 texel edge)²: distance² times this is the
        /// squared texel footprint ratio whose halved log2 is the imagery level.
        pub imagery_scale_sq: f32,
        /// Squared `tlm.radial_bands_m` (`TLM_RADIAL_BANDS` used, the 4th is +∞), m².
        pub radial_band_sq_m2: [f32; 4],
        /// Viewport (= depth target) size, pixels.
        pub screen_px: [u32; 2],
        /// NDC units per pixel (2 / width, 2 / height).
        pub ndc_per_px: [f32; 2],
        /// Mips of the depth pyramid: the occlusion test reads none coarser than `hiz_mips - 1`.
        pub hiz_mips: u32,
        /// Imagery levels (0: no imagery).
        pub imagery_levels: u32,
        /// Entries of `height_lod_range_m` in use (the terrain's LOD count).
        pub height_lod_count: u32,
        /// Rings in use this frame (at most `TLM_MAX_RINGS`): the dispatch's z extent.
        pub rings: u32,
        /// Cells per ring side.
        pub cells: u32,
        /// Corner colours C of the seed patterns (`tlm.patterns` = C⁴): a ring-0 cell's
        /// visibility is 1 + its pattern, the one of its four corners' hashed colours.
        pub corner_colours: u32,
        /// The world's seed number (`tlm.seed`): the germ of every ring-0 cell's pattern hash.
        pub seed: u32,
        /// Always 0: OR-ed into every product so no compiler fuses it into an FMA (see the shader).
        pub no_fuse: u32,
        /// A box is hidden when it lies more than `occlusion_tolerance_m + per_m × distance`
        /// behind the depth (`config::OcclusionTolerance`, as the seeds').
        pub occlusion_tolerance_per_m: f32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 3],
        /// How a cell's camera-relative grid box bends onto the Earth (`earth::horizon::EarthBend`:
        /// its fall per m² and its margins across per m, m² and m³; then up and down per m, m²
        /// and m⁴); all 0 on the flat sheet.
        pub earth_bend: [[f32; 4]; 2],
        /// The horizon's cone (`earth::horizon::HorizonCone::gpu`): rows of scaled space from
        /// camera-relative space, then its axis with tangent² (w); `HorizonCone::GPU_NONE` when
        /// nothing is hidden (flat, the eye below the ground, or `terrain.horizon_culling` off).
        pub horizon: [[f32; 4]; 4],
        /// The terrain's CDLOD range of each LOD (`Lods::range_m`), metres, four per vec4.
        pub height_lod_range_m: [[f32; 4]; MAX_LEVELS as usize / 4],
        /// Height pyramid per level: first tile index, tiles along x, tiles along y, 0.
        pub height_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// Each ring's origin and height level, the first `rings` in use.
        pub rings_info: [TlmRing; TLM_MAX_RINGS as usize],
    }
}
