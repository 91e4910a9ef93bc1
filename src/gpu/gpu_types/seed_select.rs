//! Seed selection's structs (pass 3): per-frame constants, cells, species and class tables, the records it writes and its counters.

use bytemuck::{Pod, Zeroable};

use super::EarthNode;
use crate::gpu::layout::{MAX_LEVELS, MAX_SPECIES_PER_CLASS};
use crate::gpu::struct_layout::gpu_struct;

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
        /// The farthest the wind moves any point of a plant, per metre of its height
        /// (`seeds::wind::Wind::reach_per_height`): plants' spheres grow by it, and their summits
        /// rise and come nearer by it, so a swaying crown is never culled; 0 in still air.
        pub wind_reach_per_height: f32,
        /// Cells of the frame (`SeedFrame::cells`): rows of the dispatch grid.
        pub cell_count: u32,
        /// Page tables per level (first entry, tiles along x, tiles along y, 0).
        pub height_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// The land-cover page table per LCC level, laid out as `height_levels` (0 without land
        /// cover).
        pub lcc_levels: [[u32; 4]; 4],
        /// The imagery page table per level, laid out as `height_levels` (0 without imagery).
        pub imagery_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// The imagery's vegetation index (`dataset::vegetation`): 1 where its alpha carries it,
        /// else 0 (x); where growth starts (`seeds.vegetation_bare`, y) and 1 / the span to full
        /// growth (z); w unused.
        pub vegetation: [f32; 4],
        /// 1: a seed reads its class up to half a texel away (`seeds.class_edge_dither`); 0: at its
        /// own point.
        pub class_edge_dither: u32,
        /// How far a straight segment dips below the line between its ends' heights over the
        /// grid, at the grid's fraction t of the way: `t (1 − t) (L² + 2 Δz²)` times this, for a
        /// segment L long over the grid rising Δz (1 / 2R, from `earth`'s curvature: the Earth's
        /// fall under it, and the verticals' convergence); 0 on the flat sheet. The occlusion
        /// march's segment sags by it.
        pub chord_sag_per_m2: f32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 2],
    }
}

gpu_struct! {
    /// One ring-0 TLM cell whose seeds pass 3 checks. WGSL: `SeedCell` in `shaders/seed_select.wgsl`.
    /// The cell's corner is given in each layer's own texel grid as an integer part and a remainder,
    /// so no large coordinate ever reaches f32.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedCell {
        /// South-west corner's grid offset from the camera, metres (on the flat sheet, its
        /// camera-relative position): what the occlusion march walks the grid from.
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
        /// The mapping of its south-west corner at height 0 (`PlacedView::node`): a seed at grid
        /// offset (x, y) from the corner and height h stands at `earth_position_m(earth, (x, y,
        /// h))`, along its up there. Flat, the identity from the corner's `rel_m`.
        pub earth: EarthNode,
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
        /// How much the wind bends it (`seeds::wind::bend_of`): 1 a plant, 0 a rock; its bounds
        /// grow by this times `SeedUniforms::wind_reach_per_height` times its height.
        pub wind_bend: f32,
        /// How many models its species has (`classes::Species::variants`, on each of its
        /// entries): a seed of the entry a rule names is drawn as entry
        /// `index + seed_variant(hash, variants)`.
        pub variants: u32,
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
        /// How many draw LODs its seeds use, nearest first (`classes::Class::seed_lods`): a seed
        /// beyond the last is culled by distance, and one in the last fades out at its end
        /// (`SpeciesLod::last`). 0 for a palette index without a class, which grows nothing.
        pub lods: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 3],
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
    /// Pass 3's second round (`shaders/seed_select_blocks.wgsl`): the indirect dispatch its
    /// `settle` writes, wgpu's `DispatchIndirectArgs`: no workgroups when nothing overflowed, else
    /// the first round's grid in two layers along z (which tells the round apart). WGSL:
    /// `SeedSettle`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Default)]
    pub struct SeedSettle {
        /// Workgroups along x: per cell.
        pub groups_x: u32,
        /// Workgroups along y: the cells.
        pub groups_y: u32,
        /// 2: layer 0 returns at once, layer 1 selects again into the settled blocks.
        pub groups_z: u32,
    }
}
