// One selected seed, as pass 3 writes it and pass 4 draws it. Rust: `SeedRecord` in
// src/gpu/gpu_types.rs (sizes checked by tests/shaders.rs).
struct SeedRecord {
    position_rel_m: vec3<f32>,
    height_m: f32,
    address: vec2<i32>,
    rank: u32,
    species_lod: u32,
    jitter: u32,
    ground_colour: u32,
    radius_m: f32,
    ground_m: f32,
}
