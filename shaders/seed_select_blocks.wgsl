// Pass 3's output: where each workgroup's survivors go (part of the seed_select shader, after
// seed_select.wgsl, whose bindings and `select_seed` it uses).
//
// `main` runs twice. First (one layer of workgroups along z) every workgroup selects its seeds,
// ballots the survivors, claims room for them with one global atomic and writes them; its
// block-table entry holds the whole count, even past `capacity`. Which workgroups found room
// depends on the order the atomics landed in, so when anything overflowed, `settle` (one
// workgroup) renumbers the table in table order by a prefix sum of those counts, keeping the first
// `capacity` records as the twin does, and dispatches `main` again, indirectly, with two layers:
// the second round is told apart by the grid alone (a flag in a buffer could not be both the
// indirect argument and bound for `main`), layer 0 returns at once, and in layer 1 each workgroup
// whose settled block keeps anything selects its seeds again (the same decisions) and writes the
// first `count` survivors at its settled offset. Without overflow `settle` dispatches nothing and
// the first round's table stands (its offsets vary, its order does not).

// The indirect dispatch `settle` writes: wgpu's DispatchIndirectArgs.
struct SeedSettle {
    groups_x: u32,
    groups_y: u32,
    groups_z: u32,
}

@group(1) @binding(0) var<storage, read_write> settled: SeedSettle;

var<workgroup> wg_count: array<atomic<u32>, SEED_COUNTERS>;
var<workgroup> wg_kept: array<atomic<u32>, BALLOT_WORDS>;
var<workgroup> wg_word: u32;
var<workgroup> wg_scan: array<u32, SEED_WORKGROUP>;

// Workgroups per cell: a pattern's active ranks, a block of SEED_WORKGROUP at a time.
fn groups_per_cell() -> u32 {
    return (u.active_ranks + SEED_WORKGROUP - 1u) / SEED_WORKGROUP;
}

@compute @workgroup_size(SEED_WORKGROUP)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>,
        @builtin(local_invocation_index) lane: u32) {
    let table = group.y * groups.x + group.x;
    let redo = groups.z == 2u;
    if redo {
        if group.z == 0u {
            return;
        }
        // A block past `capacity` keeps nothing: it need not select again.
        if lane == 0u {
            wg_word = blocks[table].count;
        }
        if workgroupUniformLoad(&wg_word) == 0u {
            return;
        }
    }
    if lane < SEED_COUNTERS {
        atomicStore(&wg_count[lane], 0u);
    }
    if lane < BALLOT_WORDS {
        atomicStore(&wg_kept[lane], 0u);
    }
    workgroupBarrier();
    let rank = group.x * SEED_WORKGROUP + lane;
    var outcome: Outcome;
    let in_pattern = rank < u.active_ranks;
    if in_pattern {
        outcome = select_seed(cells[group.y], rank);
        if outcome.count == COUNT_SELECTED {
            atomicOr(&wg_kept[lane / 32u], 1u << (lane % 32u));
        } else {
            atomicAdd(&wg_count[outcome.count], 1u);
        }
    }
    workgroupBarrier();
    var kept_mask: array<u32, BALLOT_WORDS>;
    for (var w = 0u; w < BALLOT_WORDS; w += 1u) {
        kept_mask[w] = atomicLoad(&wg_kept[w]);
    }
    let survivor = in_pattern && outcome.count == COUNT_SELECTED;
    let below = ballot_below(kept_mask, lane);
    if redo {
        let block = blocks[table];
        if survivor && below < block.count {
            records[block.offset + below] = outcome.record;
            keys[block.offset + below] = outcome.key;
        }
        return;
    }
    if lane == 0u {
        let kept = ballot_count(kept_mask);
        var block = SeedBlock(0u, 0u);
        if kept != 0u {
            let base = atomicAdd(&counters.count[COUNT_SELECTED], kept);
            let room = select(0u, u.capacity - base, base < u.capacity);
            if kept > room {
                atomicAdd(&counters.count[COUNT_OVERFLOW], kept - room);
            }
            block = SeedBlock(base, kept);
            wg_word = base;
        }
        blocks[table] = block;
        let checked = min(SEED_WORKGROUP, u.active_ranks - group.x * SEED_WORKGROUP);
        atomicAdd(&counters.count[COUNT_CHECKED], checked);
        for (var c = COUNT_CHECKED + 1u; c < SEED_COUNTERS; c += 1u) {
            let n = atomicLoad(&wg_count[c]);
            if n != 0u {
                atomicAdd(&counters.count[c], n);
            }
        }
    }
    let index = workgroupUniformLoad(&wg_word) + below;
    if survivor && index < u.capacity {
        records[index] = outcome.record;
        keys[index] = outcome.key;
    }
}

// One workgroup, after the first round of `main`: without overflow, dispatches nothing; with it,
// settles every block in table order (offset: the survivors of the blocks before it; count: as
// many as fit, offset 0 when none does) and dispatches the second round.
@compute @workgroup_size(SEED_WORKGROUP)
fn settle(@builtin(local_invocation_index) lane: u32) {
    if lane == 0u {
        wg_word = atomicLoad(&counters.count[COUNT_OVERFLOW]);
    }
    let overflowed = workgroupUniformLoad(&wg_word) != 0u;
    if lane == 0u {
        settled = SeedSettle(select(0u, groups_per_cell(), overflowed), u.cell_count, 2u);
    }
    if !overflowed {
        return;
    }
    let total = groups_per_cell() * u.cell_count;
    var before_chunk = 0u;
    for (var first = 0u; first < total; first += SEED_WORKGROUP) {
        let entry = first + lane;
        var kept = 0u;
        if entry < total {
            kept = blocks[entry].count;
        }
        // Inclusive prefix sum over the chunk (Hillis and Steele: log2 steps, read then write).
        wg_scan[lane] = kept;
        workgroupBarrier();
        for (var step = 1u; step < SEED_WORKGROUP; step <<= 1u) {
            var add = 0u;
            if lane >= step {
                add = wg_scan[lane - step];
            }
            workgroupBarrier();
            wg_scan[lane] += add;
            workgroupBarrier();
        }
        let before = before_chunk + wg_scan[lane] - kept;
        if entry < total {
            let count = min(kept, select(0u, u.capacity - before, before < u.capacity));
            blocks[entry] = SeedBlock(select(0u, before, count != 0u), count);
        }
        if lane == SEED_WORKGROUP - 1u {
            wg_word = wg_scan[lane];
        }
        before_chunk += workgroupUniformLoad(&wg_word);
    }
}
