//! Compaction's CPU half: what a pass is sized for, and what it writes, as CPU data.

use crate::config::Settings;
use crate::gpu::gpu_types::SeedDrawArgs;
use crate::gpu::layout::SEED_GROUPS;
use crate::seeds::block_capacity;

/// What a compaction pass is sized for: block-table entries and records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompactLimits {
    /// Block-table entries one run may compact (`seeds::block_capacity`): what pass 3 can fill.
    pub blocks: u32,
    /// Seed records the record buffer holds (`seeds.capacity`): the length of the permutation `order`.
    pub records: u32,
}

impl From<&Settings> for CompactLimits {
    fn from(settings: &Settings) -> Self {
        Self { blocks: block_capacity(settings.seeds.seeds_per_pattern), records: settings.seeds.capacity }
    }
}

/// What compaction wrote (GPU readback or CPU twin).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Compacted {
    /// Draw slot → record index, groups one after the other (`drawn()` slots).
    pub order: Vec<u32>,
    /// `SEED_DRAWS` indirect draws: one per group, then each group's cross-fade draw.
    pub args: Vec<SeedDrawArgs>,
}

impl Compacted {
    /// Slots filled: the records of every group.
    pub fn drawn(&self) -> usize {
        self.args.iter().take(SEED_GROUPS as usize).map(|a| a.instance_count as usize).sum()
    }

    /// The records in draw order, from the record buffer `order` indexes.
    pub fn gather<T: Copy>(&self, records: &[T]) -> Vec<T> {
        self.order.iter().map(|&i| records[i as usize]).collect()
    }
}
