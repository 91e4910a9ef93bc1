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

// The colour, of `colours`, of lattice corner (x, y) of the ring-0 grid (south-west of cell (x, y)).
fn corner_colour(x: u32, y: u32, seed: u32, colours: u32) -> u32 {
    return pattern_hash(x, y, seed) % colours;
}

// The seed pattern of ring-0 cell `g`: the one of its four corners' colours, c00 + C (c10 + C (c01
// + C c11)) (src/seeds/patterns: neighbours agree across their border).
fn cell_pattern(g: vec2<u32>, seed: u32, colours: u32) -> u32 {
    let c00 = corner_colour(g.x, g.y, seed, colours);
    let c10 = corner_colour(g.x + 1u, g.y, seed, colours);
    let c01 = corner_colour(g.x, g.y + 1u, seed, colours);
    let c11 = corner_colour(g.x + 1u, g.y + 1u, seed, colours);
    return c00 + colours * (c10 + colours * (c01 + colours * c11));
}
