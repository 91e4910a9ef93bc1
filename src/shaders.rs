//! How it works: WGSL sources are compiled into the binary, each prefixed with a prelude generated
//! from the Rust constants it needs, so a tile size or a capacity is written once (in Rust) and
//! can never disagree between the CPU and the shaders. Tests validate every source with naga.

use crate::dataset::{
    CELL_TILE_TEXELS, HEIGHT_BORDER, HEIGHT_TILE_CELLS, IMAGERY_BORDER, IMAGERY_MIPS, LayerSpec,
};
use crate::passes::compact;
use crate::seeds;

/// Levels a page table describes at most (a 2^15-tile-wide layer).
pub const MAX_LEVELS: u32 = 16;

/// Every shader: its name (matching its Rust module) and its source, as parts: shared code from
/// `shaders/shared/` first, then the file of the same name.
/// The terrain mesh both terrain passes draw.
const TERRAIN_MESH: &str = include_str!("../shaders/shared/terrain_mesh.wgsl");
/// The hashes that pick seed patterns and vary seeds.
const HASH: &str = include_str!("../shaders/shared/hash.wgsl");
/// One selected seed, shared by the pass that writes it and the pass that draws it.
const SEED_RECORD: &str = include_str!("../shaders/shared/seed_record.wgsl");
/// How pass 3 hands its survivors to compaction: the block table's entries and lane ballots.
const BLOCKS: &str = include_str!("../shaders/shared/blocks.wgsl");

pub const SHADERS: &[(&str, &[&str])] = &[
    ("terrain", &[TERRAIN_MESH, include_str!("../shaders/terrain.wgsl")]),
    ("ground", &[TERRAIN_MESH, include_str!("../shaders/ground.wgsl")]),
    ("depth_pyramid", &[include_str!("../shaders/depth_pyramid.wgsl")]),
    ("tile_load_map", &[HASH, include_str!("../shaders/tile_load_map.wgsl")]),
    ("seed_select", &[HASH, BLOCKS, SEED_RECORD, include_str!("../shaders/seed_select.wgsl")]),
    ("compact", &[BLOCKS, include_str!("../shaders/compact.wgsl")]),
    ("draw_seeds", &[SEED_RECORD, include_str!("../shaders/draw_seeds.wgsl")]),
];

/// The constants every shader sees, generated from their Rust definitions.
pub fn prelude() -> String {
    let height = LayerSpec::heights([1, 1]).pyramid;
    let imagery = LayerSpec::imagery([1, 1]).pyramid;
    let constants = [
        ("HEIGHT_TILE_CELLS", HEIGHT_TILE_CELLS),
        ("HEIGHT_BORDER", HEIGHT_BORDER),
        ("HEIGHT_TILE_EXTENT", height.tile_extent()),
        ("IMAGERY_TILE_TEXELS", CELL_TILE_TEXELS),
        ("IMAGERY_BORDER", IMAGERY_BORDER),
        ("IMAGERY_TILE_EXTENT", imagery.tile_extent()),
        ("IMAGERY_MIPS", IMAGERY_MIPS),
        ("MAX_LEVELS", MAX_LEVELS),
        ("HIZ_WORKGROUP", crate::passes::depth_pyramid::HIZ_WORKGROUP),
        ("TLM_WORKGROUP", crate::passes::tile_load_map::TLM_WORKGROUP),
        ("TLM_MAX_RINGS", crate::passes::tile_load_map::TLM_MAX_RINGS),
        ("TLM_SPAN_INSIDE", crate::passes::tile_load_map::TLM_SPAN_INSIDE),
        ("TLM_SPAN_COVERED", crate::passes::tile_load_map::TLM_SPAN_COVERED),
        ("LCC_LEVELS", crate::lcc::LCC_LEVELS),
        ("LCC_TILE_TEXELS", CELL_TILE_TEXELS),
        ("MAX_SPECIES_PER_CLASS", crate::classes::MAX_SPECIES_PER_CLASS as u32),
        ("SEED_WORKGROUP", seeds::SEED_WORKGROUP),
        ("SEED_SALT", seeds::SEED_SALT),
        ("GROUND_SAMPLES", seeds::GROUND_SAMPLES),
        ("SEED_COUNTERS", seeds::SEED_COUNTERS),
        ("COUNT_SELECTED", seeds::COUNT_SELECTED),
        ("COUNT_OVERFLOW", seeds::COUNT_OVERFLOW),
        ("COUNT_CHECKED", seeds::COUNT_CHECKED),
        ("COUNT_CLASS", seeds::COUNT_CLASS),
        ("COUNT_RULE", seeds::COUNT_RULE),
        ("COUNT_DISTANCE", seeds::COUNT_DISTANCE),
        ("COUNT_FRUSTUM", seeds::COUNT_FRUSTUM),
        ("COUNT_OCCLUSION", seeds::COUNT_OCCLUSION),
        ("BALLOT_WORDS", seeds::BALLOT_WORDS),
        ("SEED_LODS", seeds::SEED_LODS),
        ("SEED_GROUPS", seeds::SEED_GROUPS),
        ("SEED_DRAWS", seeds::SEED_DRAWS),
        ("MATERIAL_TEXTURED", crate::gpu::gpu_types::MATERIAL_TEXTURED),
        ("MATERIAL_REPEAT", crate::gpu::gpu_types::MATERIAL_REPEAT),
        ("COMPACT_WORKGROUP", compact::COMPACT_WORKGROUP),
        ("COMPACT_CHUNK", compact::COMPACT_CHUNK),
    ];
    let mut text = String::from("// Generated from Rust constants (src/shaders.rs).\n");
    for (name, value) in constants {
        text.push_str(&format!("const {name}: u32 = {value}u;\n"));
    }
    text.push_str(&format!("const OCCLUSION_FOOTPRINT_PX: i32 = {};\n", seeds::OCCLUSION_FOOTPRINT_PX));
    text
}

/// The full source of shader `name`: prelude, then its parts.
pub fn source(name: &str) -> Option<String> {
    SHADERS.iter().find(|(n, _)| *n == name).map(|(_, parts)| format!("{}\n{}", prelude(), parts.join("\n")))
}

/// Builds shader `name` on `device`.
pub fn module(device: &wgpu::Device, name: &str) -> wgpu::ShaderModule {
    let source = source(name).unwrap_or_else(|| panic!("no shader named {name}: add it to SHADERS"));
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}
