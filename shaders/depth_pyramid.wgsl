// Depth pyramid (Hi-Z): each texel of a level holds the minimum reversed-Z depth, i.e. the
// farthest surface, of the region of the level below it covers. Level 0 halves the depth target.
//
// Sizes halve rounding down (as wgpu's mip sizes do), so at an odd edge the last texel takes the
// last three texels below it (and a 1-texel-wide source, its single texel): every source texel
// belongs to exactly the texel `min(x >> 1, size - 1)`, which is how readers map pixels to texels.

@group(0) @binding(0) var source_depth: texture_depth_2d;
@group(0) @binding(1) var destination: texture_storage_2d<r32float, write>;
@group(0) @binding(2) var source_mip: texture_2d<f32>;

// First and last source texel along one axis covered by destination texel `x`.
fn covered(x: u32, destination_size: u32, source_size: u32) -> vec2<u32> {
    let first = min(2u * x, source_size - 1u);
    let last = select(2u * x + 1u, source_size - 1u, x + 1u == destination_size);
    return vec2<u32>(first, min(last, source_size - 1u));
}

@compute @workgroup_size(HIZ_WORKGROUP, HIZ_WORKGROUP, 1)
fn reduce_depth(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(destination);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let source_size = textureDimensions(source_depth);
    let xs = covered(id.x, size.x, source_size.x);
    let ys = covered(id.y, size.y, source_size.y);
    var farthest = textureLoad(source_depth, vec2<u32>(xs.x, ys.x), 0);
    for (var y = ys.x; y <= ys.y; y += 1u) {
        for (var x = xs.x; x <= xs.y; x += 1u) {
            farthest = min(farthest, textureLoad(source_depth, vec2<u32>(x, y), 0));
        }
    }
    textureStore(destination, id.xy, vec4<f32>(farthest, 0.0, 0.0, 0.0));
}

@compute @workgroup_size(HIZ_WORKGROUP, HIZ_WORKGROUP, 1)
fn reduce_mip(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(destination);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let source_size = textureDimensions(source_mip);
    let xs = covered(id.x, size.x, source_size.x);
    let ys = covered(id.y, size.y, source_size.y);
    var farthest = textureLoad(source_mip, vec2<u32>(xs.x, ys.x), 0).r;
    for (var y = ys.x; y <= ys.y; y += 1u) {
        for (var x = xs.x; x <= xs.y; x += 1u) {
            farthest = min(farthest, textureLoad(source_mip, vec2<u32>(x, y), 0).r);
        }
    }
    textureStore(destination, id.xy, vec4<f32>(farthest, 0.0, 0.0, 0.0));
}
