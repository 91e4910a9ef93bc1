// Pass 4a, compaction: pass 3's survivors, grouped by draw group (species × SEED_LODS + radial
// LOD) without holes, in a deterministic order: group by group, and within a group in block-table
// order, then lane (rank) order inside a block, so the result equals the CPU twin
// (`reference/compact.rs`) bit for bit. The output is a permutation, `order[slot]` = index of the
// record (in pass 3's record buffer) drawn at `slot`; group g fills the slots
// [args[g].first_instance, + args[g].instance_count), and `args` are the indirect draws: each
// group's own, then at SEED_GROUPS + g the same instances with the next LOD's geometry (from the
// templates there), which the seeds in the outer band of their LOD cross-fade into.
//
// Reduce then scan, over chunks of COMPACT_CHUNK blocks (one workgroup each, one lane per block):
//   `reduce`  each lane counts its block's records per group into its row of a block × group
//             table, and lane g sums column g: the chunk's count of group g;
//   `scan`    one workgroup per group turns its column of chunk counts into exclusive prefixes
//             and writes the group's total;
//   `finish`  turns the totals into each group's first slot and fills the draw arguments;
//   `scatter` counts the rows again, lane g turns column g into each block's first slot in group
//             g (group start + chunk prefix + the blocks before), and each lane walks its block's
//             records in order, giving each the next slot of its group.
// No atomics: every count has one writer, every position follows from the table's order.

struct CompactParams {
    blocks: u32,
    chunks: u32,
    _pad: vec2<u32>,
}

struct SeedDrawArgs {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

// Constants in a storage buffer, not a uniform buffer: see tile_load_map.wgsl.
@group(0) @binding(0) var<storage, read> params: CompactParams;
@group(0) @binding(1) var<storage, read> blocks: array<SeedBlock>;
@group(0) @binding(2) var<storage, read> keys: array<u32>;
@group(0) @binding(3) var<storage, read> templates: array<SeedDrawArgs, SEED_DRAWS>;
// Chunk counts, group-major (`g × chunks + chunk`); after `scan`, exclusive prefixes.
@group(0) @binding(4) var<storage, read_write> chunk_counts: array<u32>;
@group(0) @binding(5) var<storage, read_write> args: array<SeedDrawArgs, SEED_DRAWS>;
@group(0) @binding(6) var<storage, read_write> order: array<u32>;

var<workgroup> wg_rows: array<u32, COMPACT_CHUNK * SEED_GROUPS>;
var<workgroup> wg_sums: array<u32, COMPACT_WORKGROUP>;
var<workgroup> wg_totals: array<u32, SEED_GROUPS>;

// The group of record `index`; SEED_GROUPS (none: not drawn) outside the keys or the groups.
fn key_at(index: u32) -> u32 {
    if index >= arrayLength(&keys) {
        return SEED_GROUPS;
    }
    return min(keys[index], SEED_GROUPS);
}

// Lane `lane`'s block of chunk `chunk` (empty beyond the table), its records counted per group
// into row `lane` of `wg_rows`. Called by every lane, in uniform control flow.
fn count_row(chunk: u32, lane: u32) -> SeedBlock {
    // The lanes clear the table together, neighbouring lanes neighbouring words, which a SIMD
    // group of lanes stores at once (a row per lane would be a scatter).
    for (var i = lane; i < COMPACT_CHUNK * SEED_GROUPS; i += COMPACT_CHUNK) {
        wg_rows[i] = 0u;
    }
    workgroupBarrier();
    let row = lane * SEED_GROUPS;
    let w = chunk * COMPACT_CHUNK + lane;
    var block = SeedBlock(0u, 0u);
    if w < params.blocks {
        block = blocks[w];
        block.count = min(block.count, SEED_WORKGROUP);
    }
    for (var k = 0u; k < block.count; k += 1u) {
        let key = key_at(block.offset + k);
        if key < SEED_GROUPS {
            wg_rows[row + key] += 1u;
        }
    }
    return block;
}

@compute @workgroup_size(COMPACT_CHUNK)
fn reduce(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    count_row(wg.x, lane);
    workgroupBarrier();
    if lane < SEED_GROUPS {
        var sum = 0u;
        for (var b = 0u; b < COMPACT_CHUNK; b += 1u) {
            sum += wg_rows[b * SEED_GROUPS + lane];
        }
        chunk_counts[lane * params.chunks + wg.x] = sum;
    }
}

@compute @workgroup_size(COMPACT_WORKGROUP)
fn scan(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let column = wg.x * params.chunks;
    let n = params.chunks;
    // Each lane sums a run of consecutive chunks, the lanes' sums are scanned (Hillis–Steele),
    // and each lane rewrites its run as running sums from its lane's prefix.
    let per_lane = (n + COMPACT_WORKGROUP - 1u) / COMPACT_WORKGROUP;
    let first = min(lane * per_lane, n);
    let end = min(first + per_lane, n);
    var sum = 0u;
    for (var i = first; i < end; i += 1u) {
        sum += chunk_counts[column + i];
    }
    wg_sums[lane] = sum;
    workgroupBarrier();
    for (var d = 1u; d < COMPACT_WORKGROUP; d *= 2u) {
        var v = wg_sums[lane];
        if lane >= d {
            v += wg_sums[lane - d];
        }
        workgroupBarrier();
        wg_sums[lane] = v;
        workgroupBarrier();
    }
    var running = wg_sums[lane] - sum;
    for (var i = first; i < end; i += 1u) {
        let count = chunk_counts[column + i];
        chunk_counts[column + i] = running;
        running += count;
    }
    if lane == COMPACT_WORKGROUP - 1u {
        args[wg.x].instance_count = wg_sums[lane];
    }
}

@compute @workgroup_size(SEED_GROUPS)
fn finish(@builtin(local_invocation_index) lane: u32) {
    wg_totals[lane] = args[lane].instance_count;
    workgroupBarrier();
    var first = 0u;
    for (var g = 0u; g < lane; g += 1u) {
        first += wg_totals[g];
    }
    let t = templates[lane];
    args[lane] = SeedDrawArgs(t.index_count, wg_totals[lane], t.first_index, t.base_vertex, first);
    let f = templates[SEED_GROUPS + lane];
    args[SEED_GROUPS + lane] = SeedDrawArgs(f.index_count, wg_totals[lane], f.first_index, f.base_vertex, first);
}

@compute @workgroup_size(COMPACT_CHUNK)
fn scatter(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let block = count_row(wg.x, lane);
    workgroupBarrier();
    if lane < SEED_GROUPS {
        var next = args[lane].first_instance + chunk_counts[lane * params.chunks + wg.x];
        for (var b = 0u; b < COMPACT_CHUNK; b += 1u) {
            let count = wg_rows[b * SEED_GROUPS + lane];
            wg_rows[b * SEED_GROUPS + lane] = next;
            next += count;
        }
    }
    workgroupBarrier();
    let row = lane * SEED_GROUPS;
    for (var k = 0u; k < block.count; k += 1u) {
        let index = block.offset + k;
        let key = key_at(index);
        if key < SEED_GROUPS {
            let slot = wg_rows[row + key];
            wg_rows[row + key] = slot + 1u;
            if slot < arrayLength(&order) {
                order[slot] = index;
            }
        }
    }
}
