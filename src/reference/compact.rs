//! How it works: the CPU twin of `shaders/compact.wgsl`, step for step: per chunk of
//! `COMPACT_CHUNK` blocks, each block's records are counted per group (a row of the chunk's
//! table) and the rows summed (`reduce`); each group's chunk counts become exclusive prefixes over
//! the chunks (`scan`); the groups are placed one after the other and their draws filled from the
//! templates (`finish`); each row becomes its block's first slot per group and each block's
//! records take their group's next slot in order (`scatter`). Every quantity is an integer and
//! every position follows from the order of the blocks, so the GPU must equal this exactly.

use crate::gpu::gpu_types::{SeedBlock, SeedDrawArgs};
use crate::gpu::layout::{COMPACT_CHUNK, SEED_DRAWS, SEED_GROUPS, SEED_WORKGROUP};
use crate::passes::compact::CompactError;
use crate::passes::compact::frame::Compacted;

const GROUPS: usize = SEED_GROUPS as usize;

/// The group of record `index` (the shader's `key_at`): `None` (not drawn) beyond the groups.
fn key_at(keys: &[u32], index: u32) -> Option<usize> {
    keys.get(index as usize).map(|&k| k as usize).filter(|&k| k < GROUPS)
}

/// Compacts `blocks` (entries of a block table) over `keys` (each record's draw group), with the
/// draws' mesh fields from `templates` (draw by draw, `SEED_DRAWS`; missing ones are zero). Fails when a block
/// reaches beyond `keys` or holds more than a workgroup's records: the GPU would not read those.
pub fn compact(
    keys: &[u32],
    blocks: &[SeedBlock],
    templates: &[SeedDrawArgs],
) -> Result<Compacted, CompactError> {
    for (block, b) in blocks.iter().enumerate() {
        if b.count > SEED_WORKGROUP || u64::from(b.offset) + u64::from(b.count) > keys.len() as u64 {
            return Err(CompactError::BadBlock {
                block,
                offset: b.offset,
                count: b.count,
                records: keys.len(),
            });
        }
    }
    let chunks: Vec<&[SeedBlock]> = blocks.chunks(COMPACT_CHUNK as usize).collect();
    // A chunk's rows: each block's records counted per group (the shader's `count_row`).
    let rows_of = |chunk: &[SeedBlock]| -> Vec<[u32; GROUPS]> {
        chunk
            .iter()
            .map(|b| {
                let mut row = [0; GROUPS];
                for g in (b.offset..b.offset + b.count).filter_map(|i| key_at(keys, i)) {
                    row[g] += 1;
                }
                row
            })
            .collect()
    };

    // reduce: counts[g][chunk].
    let mut counts = vec![vec![0u32; chunks.len()]; GROUPS];
    for (c, chunk) in chunks.iter().enumerate() {
        for row in rows_of(chunk) {
            for (g, n) in row.iter().enumerate() {
                counts[g][c] += n;
            }
        }
    }
    // scan: exclusive prefixes over the chunks, and each group's total.
    let mut totals = [0u32; GROUPS];
    for (g, column) in counts.iter_mut().enumerate() {
        for count in column.iter_mut() {
            let n = *count;
            *count = totals[g];
            totals[g] += n;
        }
    }
    // finish: groups one after the other; each group's cross-fade draw takes its instances.
    let mut args = Vec::with_capacity(SEED_DRAWS as usize);
    let mut first_instance = 0u32;
    for (g, &instance_count) in totals.iter().enumerate() {
        let t = templates.get(g).copied().unwrap_or_default();
        args.push(SeedDrawArgs { instance_count, first_instance, ..t });
        first_instance += instance_count;
    }
    for g in 0..GROUPS {
        let (own, t) = (args[g], templates.get(GROUPS + g).copied().unwrap_or_default());
        args.push(SeedDrawArgs {
            instance_count: own.instance_count,
            first_instance: own.first_instance,
            ..t
        });
    }
    // scatter: rows become each block's first slot per group, then records take the next one.
    let mut order = vec![0u32; first_instance as usize];
    for (c, chunk) in chunks.iter().enumerate() {
        let mut rows = rows_of(chunk);
        for g in 0..GROUPS {
            let mut next = args[g].first_instance + counts[g][c];
            for row in rows.iter_mut() {
                (row[g], next) = (next, next + row[g]);
            }
        }
        for (block, row) in chunk.iter().zip(&mut rows) {
            for index in block.offset..block.offset + block.count {
                if let Some(g) = key_at(keys, index) {
                    order[row[g] as usize] = index;
                    row[g] += 1;
                }
            }
        }
    }
    Ok(Compacted { order, args })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_keep_block_then_lane_order() {
        // Block 0 landed after block 1 in the record buffer; keys by record index.
        let keys = [5, 0, 5, 1, 0, 5];
        let blocks = [SeedBlock { offset: 3, count: 3 }, SeedBlock { offset: 0, count: 3 }];
        let out = compact(&keys, &blocks, &[]).unwrap();
        // Group 0: records 4 (block 0), 1 (block 1); group 1: 3; group 5: 5, 0, 2.
        assert_eq!(out.order, [4, 1, 3, 5, 0, 2]);
        assert_eq!((out.args[0].instance_count, out.args[0].first_instance), (2, 0));
        assert_eq!((out.args[1].instance_count, out.args[1].first_instance), (1, 2));
        assert_eq!((out.args[5].instance_count, out.args[5].first_instance), (3, 3));
        assert_eq!(out.drawn(), 6);
    }

    #[test]
    fn blocks_beyond_the_keys_are_refused() {
        let blocks = [SeedBlock { offset: 2, count: 3 }];
        assert!(matches!(compact(&[0; 4], &blocks, &[]), Err(CompactError::BadBlock { block: 0, .. })));
        let too_many = [SeedBlock { offset: 0, count: SEED_WORKGROUP + 1 }];
        assert!(compact(&[0; 100], &too_many, &[]).is_err());
    }
}
