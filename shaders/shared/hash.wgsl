// Integer hashes shared by the passes that derive the seeded world (twins: src/seeds/mod.rs).

// PCG (O'Neill), as a hash.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The seed-pattern hash of ring-0 cell (x, y) (global address, as two's-complement bits).
fn pattern_hash(x: u32, y: u32, seed: u32) -> u32 {
    return pcg(x ^ pcg(y ^ pcg(seed)));
}
