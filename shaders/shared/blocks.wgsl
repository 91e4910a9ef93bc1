// How pass 3 hands its survivors to compaction: blocks, numbered by ballots.

// Where one pass-3 workgroup wrote its survivors (`SeedBlock` in src/gpu/gpu_types.rs).
struct SeedBlock {
    offset: u32,
    count: u32,
}

// Ballots: one bit per lane of a SEED_WORKGROUP-lane block, in BALLOT_WORDS words. Lanes set their
// bit with atomicOr, which commutes, so after a barrier a flagged lane's index among the flagged
// ones (the bits below its own) is the same in every run, unlike a slot handed out by atomicAdd.

// Flagged lanes.
fn ballot_count(mask: array<u32, BALLOT_WORDS>) -> u32 {
    var words = mask;
    var n = 0u;
    for (var w = 0u; w < BALLOT_WORDS; w += 1u) {
        n += countOneBits(words[w]);
    }
    return n;
}

// Flagged lanes below `lane`.
fn ballot_below(mask: array<u32, BALLOT_WORDS>, lane: u32) -> u32 {
    var words = mask;
    var n = countOneBits(words[lane / 32u] & ((1u << (lane % 32u)) - 1u));
    for (var w = 0u; w < lane / 32u; w += 1u) {
        n += countOneBits(words[w]);
    }
    return n;
}
