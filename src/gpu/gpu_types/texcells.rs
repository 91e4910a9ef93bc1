//! The texcell pass's structs: per-frame constants and the slices it draws.

use bytemuck::{Pod, Zeroable};

use crate::gpu::layout::TEXCELL_MAX_SAMPLES;
use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// Per-frame constants of the texcell pass. WGSL: `TexcellUniforms` in `shaders/texcells.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct TexcellUniforms {
        /// Land-cover page table per level: first entry, tiles along x, tiles along y, 0.
        pub lcc_levels: [[u32; 4]; 4],
        /// Level-1 land-cover texels along x and y.
        pub lcc_size: [u32; 2],
        /// Bits per level-2 sub-code of the land-cover coding (2, 4 or 8).
        pub lcc_sub_bits: u32,
        /// The land-cover level read first: the one the texcell stage streams.
        pub lcc_level: u32,
        /// Grid-space position of level-1 land-cover texel (0, 0)'s south-west corner, metres
        /// (xy), and 1 / that texel's edge, 1/m (z); w unused.
        pub lcc_frame: [f32; 4],
        /// Distances from the camera, metres: where texcells start fading in and over how far
        /// (xy), where they start fading out and over how far (zw).
        pub fade_m: [f32; 4],
        /// The slab's thickness, metres: the slices stand at fractions of it above the ground.
        pub slab_height_m: f32,
        /// 1 / the forest samples' ground cell edge, 1/m.
        pub inv_cell_m: f32,
        /// The world's germ (`tlm.seed`), which the tiling hashes lattice vertices with.
        pub seed: u32,
        /// The sample cell each (half, triplet) shows: 2 bits (x + 2y) at bit 2 · (8 · half +
        /// triplet) (Rust: `texcell::tiling::sample_cell`).
        pub tile_cells: u32,
        /// Texels along the finest slices' side.
        pub texels: f32,
        /// Slices of the finest level, 2^N.
        pub finest_slices: u32,
        /// Largest factor the opacity correction raises a slice's transmittance to (the paper's k_M).
        pub opacity_max_factor: f32,
        /// How much texcells follow the photograph's colour under them (0 to 1): at 1 their mean
        /// seen from above is the photograph's (a ratio transfer by `sample_albedo`).
        pub ground_blend: f32,
        /// Sines of a pixel's ray's angle below the horizon under which silhouette texcells show
        /// alone (x) and over which regular ones do (y), between them dithered; 0, 0: none.
        pub silhouette_sin: [f32; 2],
        /// A pixel's footprint per metre of distance, metres: the silhouettes' 3D mip level.
        pub metres_per_px_at_1m: f32,
        /// The most samples a silhouette's ray takes through the slab.
        pub silhouette_steps: u32,
        /// Forest samples in the 3D texture, stacked along its depth.
        pub sample_count: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 3],
        /// Each forest sample's mean linear albedo seen from above (its slices composited, alpha
        /// weighted; `texcell::ForestSample::albedo_from_above`), w unused: the colour follow-up's
        /// yardstick.
        pub sample_albedo: [[f32; 4]; TEXCELL_MAX_SAMPLES as usize],
    }
}

gpu_struct! {
    /// One slice of a texcell patch, drawn as one instance. WGSL: `TexcellRecord` in
    /// `shaders/texcells.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Eq, Default)]
    pub struct TexcellRecord {
        /// The terrain node instance it stands on: its index in the terrain pass's node buffer.
        pub node: u32,
        /// `TexcellSlice`: the node's quadrant, the slice and the slice pyramid's level.
        pub slice: u32,
    }
}
