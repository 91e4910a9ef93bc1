//! Compaction's structs (pass 4a): the block table's entries, the indirect draws and the run's constants.

use bytemuck::{Pod, Zeroable};

use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// Where one pass-3 workgroup put its survivors. WGSL: `SeedBlock`. Entry `cell × workgroups per
    /// cell + workgroup` of the block table, so its index is fixed while `offset` (where its one
    /// atomic landed in the record buffer) varies, unless the records overflowed: then every
    /// offset is the survivors of the blocks before it in the table (`seed_select_blocks.wgsl`).
    /// `count` records follow it, in rank order (0 for a workgroup that kept nothing or found the
    /// buffer full; `offset` is then 0).
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
