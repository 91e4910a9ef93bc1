// The ground's colour, shared by the ground pass and the texcells over it: the imagery cache
// (bound beside the terrain mesh, `terrain::gpu::BINDINGS`) read from the finest resident level,
// or a relief tint where it has none.

@group(0) @binding(3) var imagery_tiles: texture_2d_array<f32>;
@group(0) @binding(4) var imagery_sampler: sampler;
@group(0) @binding(5) var<storage, read> imagery_page_table: array<u32>;

// Albedo when the dataset has no imagery: a hypsometric tint darkened on steep slopes.
fn tint(height_m: f32, normal: vec3<f32>) -> vec3<f32> {
    let t = clamp((height_m - u.height_range_m.x) / max(u.height_range_m.y - u.height_range_m.x, 1.0), 0.0, 1.0);
    let low = vec3<f32>(0.20, 0.32, 0.14);
    let mid = vec3<f32>(0.45, 0.40, 0.26);
    let high = vec3<f32>(0.82, 0.80, 0.78);
    let ramp = select(mix(mid, high, (t - 0.6) / 0.4), mix(low, mid, t / 0.6), t < 0.6);
    let rock = vec3<f32>(0.38, 0.35, 0.32);
    return mix(ramp, rock, smoothstep(0.6, 0.35, normal.z));
}

// The ground's albedo under grid point `grid_m`, `height_m` high with normal `normal`: the
// imagery (`imagery_albedo`'s, `imagery`), or the relief tint where it has no data or there is none.
fn ground_albedo(imagery: vec4<f32>, height_m: f32, normal: vec3<f32>) -> vec3<f32> {
    let relief = tint(height_m, normal);
    if u.imagery_texels == IMAGERY_NONE {
        return relief;
    }
    return mix(relief, imagery.rgb, imagery.a);
}

// Linear RGB, and in alpha the imagery's coverage (0 where the source had no data).
fn imagery_albedo(grid_m: vec2<f32>) -> vec4<f32> {
    return imagery_coverage(imagery_sample(grid_m));
}

// An imagery sample (`imagery_sample`) with its alpha as coverage alone (decoded where it also
// carries the vegetation index).
fn imagery_coverage(sampled: vec4<f32>) -> vec4<f32> {
    if u.imagery_texels == IMAGERY_VEGETATION {
        return vec4<f32>(sampled.rgb, vegetation_coverage(sampled.a));
    }
    return sampled;
}

// How densely plants grow at an imagery sample (`imagery_sample`) by its vegetation index, 0 to 1
// (`seeds.vegetation_*`); 1 where the imagery carries none.
fn vegetation_growth(sampled: vec4<f32>) -> f32 {
    if u.imagery_texels != IMAGERY_VEGETATION || sampled.a <= 0.0 {
        return 1.0;
    }
    return clamp((vegetation_index(sampled.a) - u.vegetation.x) * u.vegetation.y, 0.0, 1.0);
}

// Linear RGB and alpha as the imagery stores it (`IMAGERY_VEGETATION`: coded), filtered.
fn imagery_sample(grid_m: vec2<f32>) -> vec4<f32> {
    // Level-0 texel coordinates, continuous across tiles: their derivatives are the footprint.
    let texel0 = (grid_m - u.imagery_frame.xy) / u.imagery_frame.z;
    let ddx0 = dpdx(texel0);
    let ddy0 = dpdy(texel0);
    let footprint = max(length(ddx0), length(ddy0));
    let wanted = log2(max(footprint, 1e-6)) + u.imagery_frame.w;
    let last = u.imagery_level_count - 1u;
    var level = u32(clamp(floor(wanted), 0.0, f32(last)));
    var slot = PAGE_EMPTY;
    loop {
        let info = u.imagery_levels[level];
        let tile = clamp(vec2<i32>(floor(texel0 / f32(1u << level) / f32(IMAGERY_TILE_TEXELS))),
                         vec2<i32>(0), vec2<i32>(info.yz) - 1);
        slot = imagery_page_table[info.x + u32(tile.y) * info.y + u32(tile.x)];
        if slot != PAGE_EMPTY || level >= last {
            break;
        }
        level += 1u;
    }
    if slot == PAGE_EMPTY {
        return vec4<f32>(0.0);
    }
    let info = u.imagery_levels[level];
    let scale = 1.0 / f32(1u << level);
    let texel = texel0 * scale;
    let tile = clamp(floor(texel / f32(IMAGERY_TILE_TEXELS)), vec2<f32>(0.0), vec2<f32>(info.yz) - 1.0);
    let extent = f32(IMAGERY_TILE_EXTENT);
    let uv = (texel - tile * f32(IMAGERY_TILE_TEXELS) + f32(IMAGERY_BORDER)) / extent;
    // The cache is an sRGB texture: filtering happens on linear values, as it should.
    let colour = textureSampleGrad(imagery_tiles, imagery_sampler, uv, page_layer(slot),
                                   ddx0 * scale / extent, ddy0 * scale / extent);
    if u.imagery_texels == IMAGERY_PUNCHED && colour.a > 0.0 {
        // Transparent black texels added nothing but weight: the covered ones' mean colour.
        return vec4<f32>(colour.rgb / colour.a, colour.a);
    }
    return colour;
}
