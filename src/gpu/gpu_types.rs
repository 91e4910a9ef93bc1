//! How it works: every struct that crosses to a shader lives here, `#[repr(C)]` and `Pod`, named
//! exactly as its WGSL twin and defined through `gpu_struct!`, so `tests/shaders.rs` can check
//! its size, every field's offset and every scalar against the WGSL layout (`struct_layout`).
//! Fields are ordered so that WGSL's alignment rules add no hidden padding.

use bytemuck::{Pod, Zeroable};

use super::layout::{MAX_LEVELS, MAX_SPECIES_PER_CLASS, TLM_MAX_RINGS};
use super::struct_layout::{GpuLayout, StructLayout, gpu_struct};

gpu_struct! {
    /// Per-frame terrain constants. WGSL: `TerrainUniforms` in `shaders/terrain.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable)]
    pub struct TerrainUniforms {
        /// Clip space from camera-relative world space (x east, y north, z up; metres).
        pub clip_from_view_world: [[f32; 4]; 4],
        /// Unit vector towards the sun, w unused.
        pub sun_dir: [f32; 4],
        /// Haze colour (linear RGB) and, in w, the distance that hides half the ground, metres.
        pub haze: [f32; 4],
        /// Camera position in grid space (metres east/north of the grid origin, height), w unused.
        /// Grid-space positions of vertices are node origin + offset, so this stays an f32 offset.
        pub camera_grid_m: [f32; 4],
        /// Height range of the dataset (min, max), then grid cells per node, then 1 if imagery exists.
        pub height_range_m: [f32; 2],
        /// Grid cells along a node's edge, the same at every LOD: a node draws (node_cells + 3)²
        /// vertices, its skirt ring included.
        pub node_cells: u32,
        /// 1 when the dataset has imagery, which the ground pass blends over its relief tint; else 0.
        pub has_imagery: u32,
        /// Imagery: grid-space position of texel (0, 0)'s south-west corner (xy), level-0 texel edge
        /// in metres (z), level-of-detail bias in log2 texels (w).
        pub imagery_frame: [f32; 4],
        /// Imagery page table per level: first entry, tiles along x, tiles along y, 0.
        pub imagery_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// Imagery levels stored, then padding.
        pub imagery_level_count: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 3],
    }
}

gpu_struct! {
    /// One terrain node to draw. WGSL: `TerrainNode` in `shaders/terrain.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
    pub struct TerrainNode {
        /// South-west corner relative to the camera, metres (f64 on the CPU, a small f32 here).
        pub origin_rel_m: [f32; 2],
        /// Distance between the node's vertices, metres.
        pub cell_m: f32,
        /// Layer of the height cache holding the tile the node reads (its own, or while that one
        /// streams in, its finest resident ancestor).
        pub height_slot: u32,
        /// Sample position (border included) of the node's south-west vertex in that tile.
        pub sample_offset: [f32; 2],
        /// Vertices morph into the coarser grid between these distances from the camera, metres.
        pub morph_start_m: f32,
        /// Where the morph is complete: the LOD's range (`Lods::range_m`), metres from the camera.
        pub morph_end_m: f32,
        /// Cells of the node inside the dataset; vertices beyond are clamped onto its edge.
        pub cells_inside: [f32; 2],
        /// Tile samples per node cell: 1 for the node's own tile, 1/2^k for an ancestor k levels up.
        pub sample_step: f32,
        /// How far the node's skirts hang below its edges, metres.
        pub skirt_m: f32,
    }
}

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
        /// Seed patterns P (visibility of a ring-0 cell is 1 + hash % P).
        pub patterns: u32,
        /// The world's seed number (`tlm.seed`): the germ of every ring-0 cell's pattern hash.
        pub seed: u32,
        /// Always 0: OR-ed into every product so no compiler fuses it into an FMA (see the shader).
        pub no_fuse: u32,
        /// A box is hidden when it lies more than `occlusion_tolerance_m + per_m × distance`
        /// behind the depth (`config::OcclusionTolerance`, as the seeds').
        pub occlusion_tolerance_per_m: f32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 3],
        /// The terrain's CDLOD range of each LOD (`Lods::range_m`), metres, four per vec4.
        pub height_lod_range_m: [[f32; 4]; MAX_LEVELS as usize / 4],
        /// Height pyramid per level: first tile index, tiles along x, tiles along y, 0.
        pub height_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// Each ring's origin and height level, the first `rings` in use.
        pub rings_info: [TlmRing; TLM_MAX_RINGS as usize],
    }
}

gpu_struct! {
    /// Per-frame constants of seed selection (pass 3). WGSL: `SeedUniforms` in
    /// `shaders/seed_select.wgsl`. Lengths are pre-divided on the CPU (f64, then rounded once) so the
    /// shader and its twin only multiply.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
    pub struct SeedUniforms {
        /// Clip space from camera-relative world space (columns), as the terrain draws with.
        pub clip_from_view_world: [[f32; 4]; 4],
        /// Camera height in grid space, metres.
        pub camera_z_m: f32,
        /// Near plane, metres: reversed-Z depth is `near_m / view distance`.
        pub near_m: f32,
        /// NDC tolerance of the frustum test.
        pub frustum_epsilon: f32,
        /// Always 0: OR-ed into every product so no compiler fuses it into an FMA.
        pub no_fuse: u32,
        /// For the side planes `w ± x ≥ 0` (and y), the length of `row_w ± row_x` (xyz; the larger of
        /// the two): a sphere of radius r reaches a plane when `w ∓ x ≥ −r` times this, so with
        /// `frustum_epsilon` 0 the test is the exact sphere–plane test.
        pub clip_row_len: [f32; 2],
        /// Viewport (= depth target) size, pixels.
        pub screen_px: [u32; 2],
        /// A summit is hidden when it lies more than `tolerance_m + per_m × distance` behind the depth.
        pub occlusion_tolerance_m: f32,
        /// How much that tolerance grows per metre of the summit's distance
        /// (`seeds.occlusion_tolerance_per_km` / 1000).
        pub occlusion_tolerance_per_m: f32,
        /// 1 / the height that sees the full radial LOD distances, 1/m.
        pub inv_reference_height_m: f32,
        /// Fraction of its height a seed's anchor sinks below the ground.
        pub sink_fraction: f32,
        /// Each draw LOD's reach (`draw_seeds.reach_m`), metres, for seeds of the reference height.
        pub draw_reach_m: [f32; 4],
        /// A ring-0 cell's edge in level-0 height samples, in level-1 land-cover texels and in
        /// level-0 imagery texels.
        pub cell_in_samples: f32,
        /// A ring-0 cell's edge in level-1 land-cover texels (0 without land cover).
        pub cell_in_lcc_texels: f32,
        /// A ring-0 cell's edge in level-0 imagery texels (0 without imagery).
        pub cell_in_imagery_texels: f32,
        /// Ground-colour sampling radius, level-0 imagery texels.
        pub ground_radius_texels: f32,
        /// 1 / height sample spacing, 1/m (slopes).
        pub inv_spacing_m: f32,
        /// Seeds in each pattern, and patterns.
        pub seeds_per_pattern: u32,
        /// Seed records the output holds.
        pub capacity: u32,
        /// The world's seed number (the hash germ, as `tlm.seed`).
        pub seed: u32,
        /// Level-0 height samples along x and y.
        pub height_size: [u32; 2],
        /// Levels of the height pyramid (at most `MAX_LEVELS`): where the walk up to a resident
        /// level stops.
        pub height_level_count: u32,
        /// Bits per level-2 sub-code of the land-cover coding (2, 4 or 8); 0: no land cover.
        pub lcc_sub_bits: u32,
        /// Level-1 land-cover texels along x and y.
        pub lcc_size: [u32; 2],
        /// Levels of the imagery pyramid (at most `MAX_LEVELS`); 0 without imagery.
        pub imagery_level_count: u32,
        /// Edge of a ring-0 cell, metres.
        pub cell_m: f32,
        /// Imagery level-0 texels along x and y.
        pub imagery_size: [u32; 2],
        /// NDC units per pixel (2 / width, 2 / height).
        pub ndc_per_px: [f32; 2],
        /// The camera in level-0 height samples: integer part, remainder.
        pub camera_sample: [i32; 2],
        /// The remainder of the camera's position, in [0, 1) level-0 height samples.
        pub camera_sample_frac: [f32; 2],
        /// Most samples of the DEM march that settles a summit near a silhouette (0: no march; the
        /// summit's own pixel decides).
        pub refine_max_steps: u32,
        /// Ranks checked per cell: none beyond the densest class's last rank limit grows anything.
        pub active_ranks: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 2],
        /// Page tables per level (first entry, tiles along x, tiles along y, 0).
        pub height_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// The land-cover page table per LCC level, laid out as `height_levels` (0 without land
        /// cover).
        pub lcc_levels: [[u32; 4]; 4],
        /// The imagery page table per level, laid out as `height_levels` (0 without imagery).
        pub imagery_levels: [[u32; 4]; MAX_LEVELS as usize],
    }
}

gpu_struct! {
    /// One ring-0 TLM cell whose seeds pass 3 checks. WGSL: `SeedCell` in `shaders/seed_select.wgsl`.
    /// The cell's corner is given in each layer's own texel grid as an integer part and a remainder,
    /// so no large coordinate ever reaches f32.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedCell {
        /// South-west corner relative to the camera, metres.
        pub rel_m: [f32; 2],
        /// Global ring-0 address (x, y): with the rank, a seed's identity.
        pub address: [i32; 2],
        /// Corner in level-0 height samples: integer part, remainder.
        pub height_sample: [i32; 2],
        /// The remainder of that corner, in [0, 1) samples.
        pub height_frac: [f32; 2],
        /// Corner in level-1 land-cover texels (the source's).
        pub lcc_texel: [i32; 2],
        /// The remainder of that corner, in [0, 1) texels.
        pub lcc_frac: [f32; 2],
        /// Corner in level-0 imagery texels.
        pub imagery_texel: [i32; 2],
        /// The remainder of that corner, in [0, 1) texels.
        pub imagery_frac: [f32; 2],
        /// Its seed pattern, and the land-cover level its radial LOD asked the streaming for.
        pub pattern: u32,
        /// The land-cover level its seeds read first: its radial LOD, at most `LCC_LEVELS - 1`.
        pub lcc_level: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 2],
    }
}

gpu_struct! {
    /// How a species grows, as pass 3 reads it. WGSL: `SeedSpecies`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedSpecies {
        /// Height range (min, max), metres.
        pub height_m: [f32; 2],
        /// Altitude range (min, max), metres.
        pub altitude_m: [f32; 2],
        /// tan² of the steepest slope it grows on.
        pub max_slope_tan_sq: f32,
        /// Bounding-sphere radius per metre of height.
        pub radius_per_height: f32,
        /// What it is: `KIND_TREE`, `KIND_BUSH` or `KIND_ROCK`.
        pub kind: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: u32,
    }
}

gpu_struct! {
    /// The seeds of one land-cover palette index. WGSL: `SeedClass`. A seed of rank r is species
    /// `species[k]` for the first k with `r < rank_limit[k]` (cumulative densities × cell area), and
    /// none when r is beyond them all: thinning by rank keeps every density blue noise.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedClass {
        /// Per rule k, the seeds per cell that rules 0 to k grow together (cumulative densities ×
        /// cell area); 0 for an unused rule, which no rank is below.
        pub rank_limit: [f32; MAX_SPECIES_PER_CLASS as usize],
        /// The species (index into the species table) each rule grows.
        pub species: [u32; MAX_SPECIES_PER_CLASS as usize],
    }
}

gpu_struct! {
    /// One selected seed. WGSL: `SeedRecord`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedRecord {
        /// Anchor (ground, sunk by `sink_fraction` of the height) relative to the camera, metres.
        pub position_rel_m: [f32; 3],
        /// The seed's height (its size), metres.
        pub height_m: f32,
        /// Global ring-0 cell and rank in its pattern: the seed's identity.
        pub address: [i32; 2],
        /// Its rank in its cell's pattern (also what shifts its dither pattern when drawn).
        pub rank: u32,
        /// Species, draw LOD and the levels it was read from: a `layout::SpeciesLod`.
        pub species_lod: u32,
        /// Hash bits: orientation and colour variation, a `layout::SeedJitter`.
        pub jitter: u32,
        /// Mean imagery colour around the seed, linear RGB as unorm8 (alpha: imagery coverage).
        pub ground_colour: u32,
        /// Bounding-sphere radius, metres.
        pub radius_m: f32,
        /// Bilinear ground height under the seed, grid space, metres (before sinking).
        pub ground_m: f32,
    }
}

gpu_struct! {
    /// What pass 3 counted. WGSL: `SeedCounters` (atomics). `selected` counts every seed that passed,
    /// overflow included; records hold `min(selected, capacity)`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Default, serde::Serialize)]
    pub struct SeedCounters {
        /// Seeds that passed every test, overflow included.
        pub selected: u32,
        /// Selected seeds that found the record buffer full and were not written.
        pub overflow: u32,
        /// Seeds checked: every active rank of every cell dispatched.
        pub checked: u32,
        /// Culled: no class, or a class whose density leaves this rank out (or outside the dataset).
        pub class: u32,
        /// Culled by the species' altitude or slope rule.
        pub rule: u32,
        /// Beyond the radial LOD distance for its size.
        pub distance: u32,
        /// Culled: the bounding sphere lies outside the view frustum (beyond `frustum_epsilon`).
        pub frustum: u32,
        /// Culled: the summit lies more than the occlusion tolerance behind the terrain's depth.
        pub occlusion: u32,
    }
}

gpu_struct! {
    /// Where one pass-3 workgroup put its survivors. WGSL: `SeedBlock`. Entry `cell × workgroups per
    /// cell + workgroup` of the block table, so its index is fixed while `offset` (where its one
    /// atomic landed in the record buffer) varies; `count` records follow it, in rank order (0 for a
    /// workgroup that kept nothing or found the buffer full; `offset` is then 0).
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Default)]
    pub struct SeedBlock {
        /// Index in the record buffer of the workgroup's first survivor.
        pub offset: u32,
        /// Survivors recorded from `offset` on.
        pub count: u32,
    }
}

gpu_struct! {
    /// One indexed indirect draw: wgpu's `DrawIndexedIndirectArgs` layout (5 × u32). WGSL:
    /// `SeedDrawArgs` in `shaders/compact.wgsl`, which writes one per draw group; as a template (what
    /// the draw pass uploads) `instance_count` and `first_instance` are ignored.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Default)]
    pub struct SeedDrawArgs {
        /// Indices of the group's geometry (its LOD's mesh or billboard cloud).
        pub index_count: u32,
        /// Seeds drawn: the group's survivors, as compaction counted them.
        pub instance_count: u32,
        /// Where the geometry's indices start in the draw pass's index buffer.
        pub first_index: u32,
        /// Added to every index: where the geometry's vertices start in the vertex buffer.
        pub base_vertex: i32,
        /// The group's first draw slot in compaction's `order` (`INDIRECT_FIRST_INSTANCE`).
        pub first_instance: u32,
    }
}

gpu_struct! {
    /// Per-run constants of compaction. WGSL: `CompactParams` in `shaders/compact.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Default)]
    pub struct CompactParams {
        /// Entries of the block table to compact, and the chunks (workgroups) they make.
        pub blocks: u32,
        /// Chunks of `COMPACT_CHUNK` entries (rounded up): the workgroups of `reduce` and `scatter`.
        pub chunks: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 2],
    }
}

gpu_struct! {
    /// Per-frame constants of the seed-drawing pass. WGSL: `DrawSeedsUniforms` in
    /// `shaders/draw_seeds.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct DrawSeedsUniforms {
        /// The terrain's: clip space from camera-relative world space.
        pub clip_from_view_world: [[f32; 4]; 4],
        /// Unit vector towards the sun, w unused.
        pub sun_dir: [f32; 4],
        /// Haze colour (linear RGB), and the distance that hides half of what is behind it (w).
        pub haze: [f32; 4],
        /// Each draw LOD's reach (`draw_seeds.reach_m`), metres, scaled by each seed's size.
        pub draw_reach_m: [f32; 4],
        /// 1 / the seed height that gets the full reaches, 1/m: a smaller seed's reach shrinks with
        /// its height.
        pub inv_reference_height_m: f32,
        /// Fraction of its height a seed's anchor was sunk by (pass 3's), undone to measure its
        /// distance.
        pub sink_fraction: f32,
        /// The outer part of each LOD band over which a seed dithers out, as a fraction of its reach.
        pub fade_fraction: f32,
        /// How much of the ground colour the seeds take on (0 to 1).
        pub ground_blend: f32,
    }
}

gpu_struct! {
    /// How a seed vertex is coloured: a base colour times (when `flags` has `MATERIAL_TEXTURED`) a
    /// layer of the seed texture array, alpha-tested, and the draw LOD of the geometry it belongs to
    /// (0 the mesh, 1 to 3 the billboard clouds), which tells a group's own draw from its cross-fade.
    /// WGSL: `SeedMaterial` in `shaders/draw_seeds.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedMaterial {
        /// Linear RGBA, multiplied with the texel.
        pub base_colour: [f32; 4],
        /// Layer of the seed texture array it samples (with `MATERIAL_TEXTURED`).
        pub layer: u32,
        /// Fragments with alpha below this are cut out (below 0: opaque).
        pub alpha_cutoff: f32,
        /// Draw LOD of its geometry: a draw whose seeds are of another LOD is their cross-fade.
        pub lod: u32,
        /// `MATERIAL_TEXTURED` | `MATERIAL_REPEAT` (wrap texture coordinates, else clamp).
        pub flags: u32,
    }
}

gpu_struct! {
    /// A vertex of a seed's mesh or billboard cloud, model space (metres, +Y up, base at y = 0), as
    /// the draw pass uploads it; `material` indexes its `SeedMaterial` table.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedVertex {
        /// Position, model space, metres; scaled to the seed's height when drawn.
        pub position_model_m: [f32; 3],
        /// Unit normal, model space.
        pub normal_model: [f32; 3],
        /// Texture coordinates in its material's layer (wrapped or clamped per `MATERIAL_REPEAT`).
        pub uv: [f32; 2],
        /// Index into the draw pass's `SeedMaterial` table.
        pub material: u32,
    }
}

/// The layout of every struct above, for the test that checks them against their WGSL twins.
pub fn layouts() -> Vec<StructLayout> {
    vec![
        TerrainUniforms::layout(),
        TerrainNode::layout(),
        TlmCell::layout(),
        TlmSpan::layout(),
        TlmRing::layout(),
        TlmUniforms::layout(),
        SeedUniforms::layout(),
        SeedCell::layout(),
        SeedSpecies::layout(),
        SeedClass::layout(),
        SeedRecord::layout(),
        SeedCounters::layout(),
        SeedBlock::layout(),
        SeedDrawArgs::layout(),
        CompactParams::layout(),
        DrawSeedsUniforms::layout(),
        SeedMaterial::layout(),
    ]
}

/// The vertex structs, read by vertex stages through attributes (`struct_layout::vertex_attributes`),
/// each with the WGSL struct of its vertex stage's input: `(Rust, WGSL shader, WGSL struct)`.
pub fn vertex_layouts() -> Vec<(StructLayout, &'static str, &'static str)> {
    vec![(SeedVertex::layout(), "draw_seeds", "VertexIn")]
}
