//! How it works: every struct that crosses to a shader lives here, one file per pass, `#[repr(C)]`
//! and `Pod`, named exactly as its WGSL twin and defined through `gpu_struct!`, so
//! `tests/shaders.rs` can check its size, every field's offset and every scalar against the WGSL
//! layout (`struct_layout`). Fields are ordered so that WGSL's alignment rules add no hidden
//! padding.

mod atmosphere;
mod compact;
mod display;
mod draw_seeds;
mod earth;
mod seed_select;
mod terrain;
mod texcells;
mod tile_load_map;

pub use atmosphere::AtmosphereUniforms;
pub use compact::{CompactParams, SeedBlock, SeedDrawArgs};
pub use display::DisplayUniforms;
pub use draw_seeds::{DrawSeedsUniforms, SeedMaterial, SeedShape, SeedVertex};
pub use earth::{EarthNode, EarthProbePoint};
pub use seed_select::{SeedCell, SeedClass, SeedCounters, SeedRecord, SeedSettle, SeedSpecies, SeedUniforms};
pub use terrain::{TerrainNode, TerrainUniforms};
pub use texcells::{TexcellRecord, TexcellUniforms};
pub use tile_load_map::{TlmCell, TlmRing, TlmSpan, TlmUniforms};

use super::struct_layout::{GpuLayout, StructLayout};

/// The layout of every struct above, for the test that checks them against their WGSL twins.
pub fn layouts() -> Vec<StructLayout> {
    vec![
        TerrainUniforms::layout(),
        TerrainNode::layout(),
        TlmCell::layout(),
        TlmSpan::layout(),
        TlmRing::layout(),
        TlmUniforms::layout(),
        SeedUniforms::layout(),
        SeedCell::layout(),
        SeedSpecies::layout(),
        SeedClass::layout(),
        SeedRecord::layout(),
        SeedCounters::layout(),
        SeedSettle::layout(),
        SeedBlock::layout(),
        SeedDrawArgs::layout(),
        CompactParams::layout(),
        DrawSeedsUniforms::layout(),
        SeedMaterial::layout(),
        SeedShape::layout(),
        TexcellUniforms::layout(),
        TexcellRecord::layout(),
        EarthNode::layout(),
        EarthProbePoint::layout(),
        AtmosphereUniforms::layout(),
        DisplayUniforms::layout(),
    ]
}

/// The vertex structs, read by vertex stages through attributes (`struct_layout::vertex_attributes`),
/// each with the WGSL struct of its vertex stage's input: `(Rust, WGSL shader, WGSL struct)`.
pub fn vertex_layouts() -> Vec<(StructLayout, &'static str, &'static str)> {
    vec![(SeedVertex::layout(), "draw_seeds", "VertexIn")]
}
