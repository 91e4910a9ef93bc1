//! Every WGSL source (with its generated prelude) parses and validates with naga, and every GPU
//! struct has the same size in WGSL as in Rust.

use terramp::gpu::gpu_types::{TerrainNode, TerrainUniforms};
use terramp::shaders::{SHADERS, source};

fn module(name: &str) -> naga::Module {
    let text = source(name).unwrap();
    let module = naga::front::wgsl::parse_str(&text)
        .unwrap_or_else(|e| panic!("{name}.wgsl: {}", e.emit_to_string(&text)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}.wgsl does not validate: {e:?}"));
    module
}

fn wgsl_size(module: &naga::Module, name: &str) -> u32 {
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    ty.inner.size(module.to_ctx())
}

#[test]
fn every_shader_validates() {
    for (name, _) in SHADERS {
        module(name);
    }
}

#[test]
fn gpu_structs_match_their_wgsl_twins() {
    let terrain = module("terrain");
    assert_eq!(wgsl_size(&terrain, "TerrainUniforms") as usize, size_of::<TerrainUniforms>());
    assert_eq!(wgsl_size(&terrain, "TerrainNode") as usize, size_of::<TerrainNode>());
}

#[test]
fn tlm_structs_match_their_wgsl_twins() {
    use terramp::gpu::gpu_types::{TlmCell, TlmRing, TlmSpan, TlmUniforms};
    let tlm = module("tile_load_map");
    assert_eq!(wgsl_size(&tlm, "TlmUniforms") as usize, size_of::<TlmUniforms>());
    assert_eq!(wgsl_size(&tlm, "TlmRing") as usize, size_of::<TlmRing>());
    assert_eq!(wgsl_size(&tlm, "TlmSpan") as usize, size_of::<TlmSpan>());
    assert_eq!(wgsl_size(&tlm, "TlmCell") as usize, size_of::<TlmCell>());
}

#[test]
fn seed_structs_match_their_wgsl_twins() {
    use terramp::gpu::gpu_types::{SeedCell, SeedClass, SeedCounters, SeedRecord, SeedSpecies, SeedUniforms};
    let seeds = module("seed_select");
    assert_eq!(wgsl_size(&seeds, "SeedUniforms") as usize, size_of::<SeedUniforms>());
    assert_eq!(wgsl_size(&seeds, "SeedCell") as usize, size_of::<SeedCell>());
    assert_eq!(wgsl_size(&seeds, "SeedSpecies") as usize, size_of::<SeedSpecies>());
    assert_eq!(wgsl_size(&seeds, "SeedClass") as usize, size_of::<SeedClass>());
    assert_eq!(wgsl_size(&seeds, "SeedRecord") as usize, size_of::<SeedRecord>());
    assert_eq!(wgsl_size(&seeds, "SeedCounters") as usize, size_of::<SeedCounters>());
}

#[test]
fn compaction_structs_match_their_wgsl_twins() {
    use terramp::gpu::gpu_types::{CompactParams, SeedBlock, SeedDrawArgs};
    let compact = module("compact");
    assert_eq!(wgsl_size(&compact, "CompactParams") as usize, size_of::<CompactParams>());
    assert_eq!(wgsl_size(&compact, "SeedDrawArgs") as usize, size_of::<SeedDrawArgs>());
    assert_eq!(wgsl_size(&compact, "SeedBlock") as usize, size_of::<SeedBlock>());
    assert_eq!(wgsl_size(&module("seed_select"), "SeedBlock") as usize, size_of::<SeedBlock>());
    // The draw pass hands the arguments to wgpu as they are.
    assert_eq!(size_of::<SeedDrawArgs>(), size_of::<wgpu::util::DrawIndexedIndirectArgs>());
    let args = SeedDrawArgs {
        index_count: 1,
        instance_count: 2,
        first_index: 3,
        base_vertex: -4,
        first_instance: 5,
    };
    let wgpu_args = wgpu::util::DrawIndexedIndirectArgs {
        index_count: 1,
        instance_count: 2,
        first_index: 3,
        base_vertex: -4,
        first_instance: 5,
    };
    assert_eq!(bytemuck::bytes_of(&args), wgpu_args.as_bytes());
}

#[test]
fn draw_seeds_structs_match_their_wgsl_twins() {
    use terramp::gpu::gpu_types::{DrawSeedsUniforms, SeedMaterial, SeedRecord};
    let draw = module("draw_seeds");
    assert_eq!(wgsl_size(&draw, "DrawSeedsUniforms") as usize, size_of::<DrawSeedsUniforms>());
    assert_eq!(wgsl_size(&draw, "SeedMaterial") as usize, size_of::<SeedMaterial>());
    assert_eq!(wgsl_size(&draw, "SeedRecord") as usize, size_of::<SeedRecord>());
}
