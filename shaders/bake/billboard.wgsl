// Impostor baking (`terramp::bake`): draws a model's triangles orthographically onto one plane
// of its billboard cloud, into that plane's rectangle of the atlas (the viewport). Unlit base
// colour; alpha-masked materials are cut out at their cutoff and everything drawn is opaque, so
// the atlas's alpha is exactly the model's coverage.

// Twin of `BakeMaterial` in src/bake/render.rs.
struct BakeMaterial {
    base_color_factor: vec4<f32>,
    alpha_cutoff: f32,
    // 1 for glTF's MASK, 0 for OPAQUE.
    masked: u32,
    _pad: vec2<u32>,
}

// One matrix per plane, indexed by the instance: clip space of the plane's rectangle from model space.
@group(0) @binding(0) var<storage, read> clip_from_model: array<mat4x4<f32>>;
@group(1) @binding(0) var<uniform> material: BakeMaterial;
@group(1) @binding(1) var base_color: texture_2d<f32>;
@group(1) @binding(2) var base_sampler: sampler;

struct VertexIn {
    @location(0) position_model_m: vec3<f32>,
    @location(1) normal_model: vec3<f32>,
    @location(2) uv: vec2<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_main(vertex: VertexIn, @builtin(instance_index) plane: u32) -> VertexOut {
    var out: VertexOut;
    out.clip = clip_from_model[plane] * vec4<f32>(vertex.position_model_m, 1.0);
    out.uv = vertex.uv;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let colour = textureSample(base_color, base_sampler, in.uv) * material.base_color_factor;
    if material.masked != 0u && colour.a < material.alpha_cutoff {
        discard;
    }
    return vec4<f32>(colour.rgb, 1.0);
}
