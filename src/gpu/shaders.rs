//! How it works: WGSL sources are compiled into the binary. Each pass names its shader as a
//! `WgslSource` (shared parts from `shaders/shared/`, then the file of the pass's name), and every
//! source is prefixed with a prelude generated from `gpu::layout`: its constants, its packed words
//! (a struct with `pack_`/`unpack_` functions each) and its helper functions, so a tile size, a
//! capacity or a bit layout is written once, in Rust, and can never disagree between the CPU and
//! the shaders. Tests validate every source with naga.

use std::fmt::Write as _;

use super::layout::{self, PackedWord};

/// The terrain mesh both terrain passes draw.
pub const TERRAIN_MESH: &str = include_str!("../../shaders/shared/terrain_mesh.wgsl");
/// The ground's colour: the imagery cache's bindings and lookup, the relief tint.
pub const IMAGERY: &str = include_str!("../../shaders/shared/imagery.wgsl");
/// The ground that mesh draws, at any point: what seeds stand on (Rust: `dataset::surface`).
pub const TERRAIN_SURFACE: &str = include_str!("../../shaders/shared/terrain_surface.wgsl");
/// The hashes that pick seed patterns and vary seeds.
pub const HASH: &str = include_str!("../../shaders/shared/hash.wgsl");
/// One selected seed, shared by the pass that writes it and the pass that draws it.
pub const SEED_RECORD: &str = include_str!("../../shaders/shared/seed_record.wgsl");
/// Reading a land-cover class through the cache's page table (pass 3 and texcells).
pub const LANDCOVER: &str = include_str!("../../shaders/shared/landcover.wgsl");
/// The ordered dither of the cross-fades between representations (seeds' LODs, texcells).
pub const DITHER: &str = include_str!("../../shaders/shared/dither.wgsl");
/// How pass 3 hands its survivors to compaction: the block table's entries and lane ballots.
pub const BLOCKS: &str = include_str!("../../shaders/shared/blocks.wgsl");
/// The cloud shadows' field (`light`), the same for everything the sun lights.
pub const CLOUDS: &str = include_str!("../../shaders/shared/clouds.wgsl");
/// The atmosphere's model: media, phases, the shell's geometry, its tables' parametrisations.
pub const ATMOSPHERE: &str = include_str!("../../shaders/shared/atmosphere.wgsl");
/// The air for the passes that light what they draw: the light at a point, the air between it
/// and the camera, the display (bindings at `passes::atmosphere::gpu::air::AIR_GROUP`).
pub const AIR: &str = include_str!("../../shaders/shared/air.wgsl");
/// The wind's bend of a plant (`seeds::wind`), the same for every representation that draws one.
pub const WIND: &str = include_str!("../../shaders/shared/wind.wgsl");

/// One shader: its name (the pass's, matching `shaders/<name>.wgsl`) and its parts, shared code
/// first.
#[derive(Debug, Clone, Copy)]
pub struct WgslSource {
    /// The pass's name: its shader file is `shaders/<name>.wgsl`, and the module is labelled so.
    pub name: &'static str,
    /// The WGSL texts joined after the prelude: shared parts, then the pass's own file.
    pub parts: &'static [&'static str],
}

impl WgslSource {
    /// The full source: prelude, then the parts.
    pub fn source(&self) -> String {
        format!("{}\n{}", prelude(), self.parts.join("\n"))
    }

    /// Builds the shader on `device`.
    pub fn module(&self, device: &wgpu::Device) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(self.name),
            source: wgpu::ShaderSource::Wgsl(self.source().into()),
        })
    }
}

/// The constants, packed words and helpers every shader sees, generated from `gpu::layout`.
pub fn prelude() -> String {
    let mut text = String::from("// Generated from Rust (src/gpu/layout.rs): edit it there.\n");
    for (name, ty, literal) in layout::wgsl_constants() {
        let _ = writeln!(text, "const {name}: {ty} = {literal};");
    }
    for word in layout::PACKED_WORDS {
        text.push_str(&packed_word(word));
    }
    text.push_str(layout::WGSL_FUNCTIONS);
    text
}

/// A packed word's WGSL struct, and its `pack_` and `unpack_` functions (fields masked to their
/// widths, from bit 0 up, exactly as `gpu::layout`'s Rust twins do).
fn packed_word(word: &PackedWord) -> String {
    let PackedWord { name, function, fields } = word;
    let mut shift = 0;
    let (mut members, mut packed, mut unpacked) = (String::new(), Vec::new(), Vec::new());
    for field in *fields {
        let mask = layout::mask(field.bits);
        let _ = writeln!(members, "    {}: u32,", field.name);
        packed.push(format!("((v.{} & {mask:#x}u) << {shift}u)", field.name));
        unpacked.push(format!("(word >> {shift}u) & {mask:#x}u"));
        shift += field.bits;
    }
    format!(
        "\nstruct {name} {{\n{members}}}\n\nfn pack_{function}(v: {name}) -> u32 {{\n    return {};\n}}\n\n\
         fn unpack_{function}(word: u32) -> {name} {{\n    return {name}({});\n}}\n",
        packed.join(" | "),
        unpacked.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prelude_declares_every_constant_and_word() {
        let text = prelude();
        assert!(text.contains("const RADIAL_INACTIVE: u32 = 3u;"), "{text}");
        assert!(text.contains("const OCCLUSION_FOOTPRINT_PX: i32 = 1i;"), "{text}");
        assert!(text.contains("fn unpack_species_lod(word: u32) -> SpeciesLod"), "{text}");
        assert!(
            text.contains("((v.lod & 0x7u) << 8u)") && text.contains("((v.last & 0x1u) << 11u)"),
            "{text}"
        );
    }
}
