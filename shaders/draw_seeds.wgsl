// Pass 4, drawing the seeds: one indexed indirect draw per (species, radial LOD) group, whose
// instances are the draw slots compaction gave the group. An instance reads its record through
// `order`, places the group's billboard cloud (model space: metres, +Y up, base at y = 0) at the
// record's camera-relative anchor, scaled to its height and turned about the vertical by its
// jitter, and projects it like the terrain. Fragments are alpha-tested against the group's atlas
// layer, tinted a little towards the ground colour and by the seed's colour variation, lit like
// the ground and hazed like it. Near the outer edge of its LOD band a seed fades out by an ordered
// (Bayer 4×4) dither, so seeds thin out instead of popping.

struct DrawSeedsUniforms {
    clip_from_view_world: mat4x4<f32>,
    sun_dir: vec4<f32>,
    haze: vec4<f32>,
    radial_lod_m: vec4<f32>,
    inv_reference_height_m: f32,
    sink_fraction: f32,
    fade_fraction: f32,
    ground_blend: f32,
}

struct DrawSeedsGroup {
    layer: u32,
    alpha_cutoff: f32,
    inv_model_height_m: f32,
    _pad: u32,
}

@group(0) @binding(0) var<uniform> u: DrawSeedsUniforms;
@group(0) @binding(1) var<storage, read> records: array<SeedRecord>;
@group(0) @binding(2) var<storage, read> order: array<u32>;
@group(0) @binding(3) var<storage, read> groups: array<DrawSeedsGroup>;
@group(0) @binding(4) var atlases: texture_2d_array<f32>;
@group(0) @binding(5) var atlas_sampler: sampler;

struct VertexIn {
    @location(0) position_model_m: vec3<f32>,
    @location(1) normal_model: vec3<f32>,
    @location(2) uv_atlas: vec2<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) rel_m: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // Albedo tint (rgb) and fade (w, 1 = fully drawn).
    @location(3) tint: vec4<f32>,
    @location(4) @interpolate(flat) layer: u32,
    @location(5) @interpolate(flat) alpha_cutoff: f32,
    // The ground colour (rgb) and how much of it to blend in (w).
    @location(6) @interpolate(flat) ground: vec4<f32>,
}

// Model space (x, y up, z) to world (x east, y north, z up), turned by `angle` about the vertical.
fn model_to_world(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let w = vec3<f32>(v.x, -v.z, v.y);
    let c = cos(angle);
    let s = sin(angle);
    return vec3<f32>(c * w.x - s * w.y, s * w.x + c * w.y, w.z);
}

// 1 inside the seed's LOD band, falling to 0 over the last `fade_fraction` of it.
fn band_fade(record: SeedRecord, lod: u32) -> f32 {
    let ground_rel = record.position_rel_m + vec3<f32>(0.0, 0.0, record.height_m * u.sink_fraction);
    let distance_m = length(ground_rel);
    let size_scale = min(1.0, record.height_m * u.inv_reference_height_m);
    let reach = u.radial_lod_m[min(lod, 3u)] * size_scale;
    let width = max(reach * u.fade_fraction, 1e-3);
    return clamp((reach - distance_m) / width, 0.0, 1.0);
}

@vertex
fn vs_main(in: VertexIn, @builtin(instance_index) instance: u32) -> VertexOut {
    let record = records[order[instance]];
    let species = record.species_lod & 0xffu;
    let lod = (record.species_lod >> 8u) & 0xfu;
    let group = groups[min(species * SEED_LODS + lod, SEED_GROUPS - 1u)];
    let angle = f32(record.jitter & 0xffffu) * (6.2831853 / 65536.0);
    let scale = record.height_m * group.inv_model_height_m;
    let rel_m = record.position_rel_m + model_to_world(in.position_model_m * scale, angle);
    var out: VertexOut;
    out.clip = u.clip_from_view_world * vec4<f32>(rel_m, 1.0);
    out.rel_m = rel_m;
    out.normal = model_to_world(in.normal_model, angle);
    out.uv = in.uv_atlas;
    // Colour variation: brightness ±15 % and a slight shift between yellow-green and blue-green.
    let variation = f32(record.jitter >> 16u) / 65535.0 - 0.5;
    let shift = vec3<f32>(1.0 + 0.3 * variation, 1.0, 1.0 - 0.3 * variation);
    let ground = unpack4x8unorm(record.ground_colour);
    out.tint = vec4<f32>(shift * (1.0 + 0.3 * variation), band_fade(record, lod));
    out.layer = group.layer;
    out.alpha_cutoff = group.alpha_cutoff;
    out.ground = vec4<f32>(ground.rgb, ground.a * u.ground_blend);
    return out;
}

// Ordered dither threshold of a pixel, in (0, 1).
fn bayer4(pixel: vec2<u32>) -> f32 {
    let m = array<u32, 16>(0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);
    return (f32(m[(pixel.y & 3u) * 4u + (pixel.x & 3u)]) + 0.5) / 16.0;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // The atlas is sRGB: samples are linear. Sampled before any discard (uniform control flow).
    let texel = textureSample(atlases, atlas_sampler, in.uv, i32(in.layer));
    if texel.a < in.alpha_cutoff || bayer4(vec2<u32>(in.clip.xy)) > in.tint.w {
        discard;
    }
    let albedo = mix(texel.rgb, in.ground.rgb, in.ground.w) * in.tint.rgb;
    // A billboard is lit from the side facing the eye; foliage lets light wrap around.
    var normal = normalize(in.normal);
    if dot(normal, in.rel_m) > 0.0 {
        normal = -normal;
    }
    let sun = 0.55 * max(dot(normal, u.sun_dir.xyz), 0.0) + 0.35 * max(u.sun_dir.z, 0.0);
    let sky = 0.3;
    let lit = albedo * (sun + sky);
    let haze = 1.0 - exp2(-length(in.rel_m) / u.haze.w);
    return vec4<f32>(mix(lit, u.haze.rgb, haze), 1.0);
}
