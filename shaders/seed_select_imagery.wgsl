// Pass 3's reads of the imagery (Rust twin: `reference::seed_select::imagery`): the photograph
// under a seed, filtered as the ground pass drapes it (bilinear in linear light, from the finest
// resident level of each texel), the mean of GROUND_SAMPLES such reads within the ground radius,
// packed for pass 4's colour follow-up; and whether the vegetation index the imagery may carry
// lets a seed grow. Part of `seed_select.wgsl`'s module (its uniforms and bindings).

// Linear colour of level-0 imagery texel `t` from the finest resident level (alpha 0: none).
fn imagery_texel(t: vec2<u32>) -> vec4<f32> {
    var level = 0u;
    loop {
        let info = u.imagery_levels[level];
        let texel = t >> vec2<u32>(level);
        let tile = min(texel / IMAGERY_TILE_TEXELS, info.yz - 1u);
        let slot = imagery_page_table[info.x + tile.y * info.y + tile.x];
        if slot != PAGE_EMPTY {
            let local = vec2<i32>(texel - tile * IMAGERY_TILE_TEXELS + IMAGERY_BORDER);
            return textureLoad(imagery_tiles, local, page_layer(slot), 0);
        }
        if level + 1u >= u.imagery_level_count {
            return vec4<f32>(0.0);
        }
        level += 1u;
    }
    return vec4<f32>(0.0);
}

// Linear colour and coverage of the imagery at `q` (level-0 texels from `base`'s corner),
// filtered bilinearly as the ground pass filters the photograph it drapes.
fn imagery_bilinear(base: vec2<i32>, q: vec2<f32>) -> vec4<f32> {
    // Texel centres lie half a texel in.
    let centred = q - vec2<f32>(0.5);
    let below = floor(centred);
    let f = centred - below;
    let corner = base + vec2<i32>(below);
    let last = vec2<i32>(u.imagery_size) - 1;
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k += 1u) {
        let d = vec2<i32>(i32(k & 1u), i32(k >> 1u));
        let t = clamp(corner + d, vec2<i32>(0), last);
        let w = select(1.0 - f.x, f.x, d.x == 1) * select(1.0 - f.y, f.y, d.y == 1);
        var colour = imagery_texel(vec2<u32>(t));
        if u.vegetation.x != 0.0 {
            colour.a = vegetation_coverage(colour.a);
        }
        sum += w * colour;
    }
    return sum;
}

// The photograph under a seed: the mean of the imagery, filtered as the ground shows it, at
// GROUND_SAMPLES hashed points within the ground radius of `p`.
fn ground_colour(p: GridPos, hash: u32) -> u32 {
    if u.imagery_level_count == 0u {
        return 0u;
    }
    var sum = vec4<f32>(0.0);
    var h = hash;
    for (var k = 0u; k < GROUND_SAMPLES; k += 1u) {
        h = pcg(h);
        let offset = vec2<f32>(mul(unit(h) * 2.0 - 1.0, u.ground_radius_texels),
                               mul(unit(pcg(h)) * 2.0 - 1.0, u.ground_radius_texels));
        sum += imagery_bilinear(p.texel, p.frac + offset);
    }
    return pack4x8unorm(sum * (1.0 / f32(GROUND_SAMPLES)));
}

// Whether the imagery's vegetation index lets seed `hash` grow at `p` (level-0 imagery texels),
// where the imagery carries one (the caller asks): the coded alpha of the four texels around it,
// bilinear, as an index, against the ramp `seeds.vegetation_*`, by a hash of the seed's own.
// Where the imagery has no data there, the land cover alone decides.
fn vegetation_grows(p: GridPos, hash: u32) -> bool {
    // Texel centres lie half a texel in: the texel below-left of p's centre, and p's weights.
    let q = p.frac - vec2<f32>(0.5);
    let below = floor(q);
    let f = q - below;
    let base = p.texel + vec2<i32>(below);
    let last = vec2<i32>(u.imagery_size) - 1;
    var alpha = 0.0;
    var weight = 0.0;
    for (var k = 0u; k < 4u; k += 1u) {
        let d = vec2<i32>(i32(k & 1u), i32(k >> 1u));
        let t = clamp(base + d, vec2<i32>(0), last);
        let w = mul(select(1.0 - f.x, f.x, d.x == 1), select(1.0 - f.y, f.y, d.y == 1));
        let a = imagery_texel(vec2<u32>(t)).a;
        if a > 0.0 {
            alpha += mul(w, a);
            weight += w;
        }
    }
    if weight <= 0.0 {
        return true;
    }
    // `vegetation_index`, product by product.
    let index = mul(mul(alpha / weight, 255.0) - 1.0, 2.0 / f32(VEGETATION_CODE_STEPS)) - 1.0;
    let growth = clamp(mul(index - u.vegetation.y, u.vegetation.z), 0.0, 1.0);
    return unit(pcg(hash ^ VEGETATION_SALT)) < growth;
}
