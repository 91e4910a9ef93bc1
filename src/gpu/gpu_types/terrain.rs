//! The terrain passes' structs (pass 0 and the ground): per-frame constants and node instances.

use bytemuck::{Pod, Zeroable};

use crate::gpu::layout::MAX_LEVELS;
use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// Per-frame terrain constants. WGSL: `TerrainUniforms` in `shaders/terrain.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable)]
    pub struct TerrainUniforms {
        /// Clip space from camera-relative world space (x east, y north, z up; metres).
        pub clip_from_view_world: [[f32; 4]; 4],
        /// Unit vector towards the sun, w unused.
        pub sun_dir: [f32; 4],
        /// Camera position in grid space (metres east/north of the grid origin, height), w unused.
        /// Grid-space positions of vertices are node origin + offset, so this stays an f32 offset.
        pub camera_grid_m: [f32; 4],
        /// Height range of the dataset (min, max), then grid cells per node, then 1 if imagery exists.
        pub height_range_m: [f32; 2],
        /// Grid cells along a node's edge, the same at every LOD: a node draws (node_cells + 3)²
        /// vertices, its skirt ring included.
        pub node_cells: u32,
        /// How the dataset's imagery texels carry coverage: `IMAGERY_NONE` (no imagery: the relief
        /// tint shows), `IMAGERY_STRAIGHT`, `IMAGERY_PUNCHED` or `IMAGERY_VEGETATION`.
        pub imagery_texels: u32,
        /// Imagery: grid-space position of texel (0, 0)'s south-west corner (xy), level-0 texel edge
        /// in metres (z), level-of-detail bias in log2 texels (w).
        pub imagery_frame: [f32; 4],
        /// The cloud shadows (`light::CloudShadowFrame::field`): where the camera's sun ray meets
        /// the cloud layer, in noise cells modulo the period (xy), cells per metre (z), the noise
        /// threshold of a cloud's edge (w).
        pub cloud_field: [f32; 4],
        /// Noise cells that meeting point moves per metre of height (xy), the share of sunlight a
        /// cloud's core holds back (z; 0: no clouds), unused (w) (`CloudShadowFrame::shift`).
        pub cloud_shift: [f32; 4],
        /// Imagery page table per level: first entry, tiles along x, tiles along y, 0.
        pub imagery_levels: [[u32; 4]; MAX_LEVELS as usize],
        /// Imagery levels stored, then padding.
        pub imagery_level_count: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: u32,
        /// With `IMAGERY_VEGETATION`: the index where growth starts (`seeds.vegetation_bare`) and
        /// 1 / the span to full growth (`seeds.vegetation_full`); the texcells thin by it.
        pub vegetation: [f32; 2],
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
