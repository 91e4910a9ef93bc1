// Pass 4 multisampled (`draw_seeds.samples` = SEED_SAMPLES, `src/passes/draw_seeds/gpu/multisample.rs`):
// appended to draw_seeds.wgsl, whose bindings, `VertexOut`, `surface` and `faded_out` it uses.

struct CoverageOut {
    @location(0) colour: vec4<f32>,
    @builtin(sample_mask) mask: u32,
}

// The standard 4× sample positions, in an order whose first k spread over the pixel (top,
// bottom, left, right: the first two are diagonal), turned per pixel and seed.
const COVERAGE_ORDER = array<u32, 4>(0u, 3u, 2u, 1u);

// Multisampled drawing (`draw_seeds.samples` = SEED_SAMPLES): the alpha test's edge, anti-aliased.
// The alpha is sharpened to cross the cutoff over one pixel (alpha − cutoff over its change per
// pixel, centred), so a texture magnified up close keeps crisp leaf edges while a minified one
// blends. That coverage of the triangle's part of the pixel becomes a share of the samples the
// triangle covers (dithered, so the mean share is exact), and those samples are written with their
// own depth: trees behind show through the gaps, and the resolve averages the samples.
@fragment
fn fs_coverage(in: VertexOut, @builtin(sample_mask) covered: u32) -> CoverageOut {
    let s = surface(in);
    let mask = coverage_mask(in, s.alpha, s.alpha_per_px, covered);
    if mask == 0u {
        discard;
    }
    return CoverageOut(s.colour, mask);
}

// The samples of `covered` a fragment of alpha `alpha` (changing by `alpha_per_px` across the
// pixel) keeps, 0 when none (or the cross-fade gives the pixel to the other draw).
fn coverage_mask(in: VertexOut, alpha: f32, alpha_per_px: f32, covered: u32) -> u32 {
    let cutoff = materials[in.material].alpha_cutoff;
    let coverage = clamp((alpha - cutoff) / max(alpha_per_px, 1e-4) + 0.5, 0.0, 1.0);
    // A dither of its own, not the cross-fade's (the two would be correlated).
    let pixel = vec2<u32>(in.clip.xy);
    let wanted = u32(coverage * f32(countOneBits(covered)) + bayer4(pixel, u32(in.keep.z) + 7u));
    if wanted == 0u || faded_out(in) {
        return 0u;
    }
    // Turned by the seed's own dither shift, never by where its record landed: pass 3's blocks land
    // in a different order every frame, and the samples kept would change with it.
    let turn = (pixel.x + 2u * pixel.y + u32(in.keep.z)) % SEED_SAMPLES;
    var mask = 0u;
    var taken = 0u;
    for (var k = 0u; k < SEED_SAMPLES; k++) {
        let bit = 1u << COVERAGE_ORDER[(k + turn) % SEED_SAMPLES];
        if taken < wanted && (covered & bit) != 0u {
            mask |= bit;
            taken++;
        }
    }
    return mask;
}

// The depth prepass multisampled: the samples `fs_coverage` would keep, depth only.
@fragment
fn fs_depth_coverage(in: VertexOut, @builtin(sample_mask) covered: u32) -> CoverageOut {
    let alpha = texel_of(in, materials[in.material]).a;
    let mask = coverage_mask(in, alpha, fwidth(alpha), covered);
    if mask == 0u {
        discard;
    }
    return CoverageOut(vec4<f32>(0.0), mask);
}

// Multisampled shading after the prepass: the equal depth test keeps exactly the samples the
// prepass wrote, so no mask is computed again (the cross-fade's dither still decides between a
// seed's two draws, whose geometry may coincide).
@fragment
fn fs_shade_samples(in: VertexOut) -> @location(0) vec4<f32> {
    if faded_out(in) {
        discard;
    }
    return surface(in).colour;
}

// Multisampled drawing starts from the frame as the ground passes left it: each pixel's colour
// (a copy of the frame's) and the terrain's depth written to all of its samples, by one triangle
// over the whole view.
@group(0) @binding(8) var frame_colour: texture_2d<f32>;
@group(0) @binding(9) var frame_depth: texture_depth_2d;

@vertex
fn vs_fill(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((vertex << 1u) & 2u), f32(vertex & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

struct FillOut {
    @location(0) colour: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_fill(@builtin(position) position: vec4<f32>) -> FillOut {
    let texel = vec2<i32>(position.xy);
    return FillOut(textureLoad(frame_colour, texel, 0), textureLoad(frame_depth, texel, 0));
}
