// Terrain: CDLOD nodes displaced by height tiles, shaded with imagery through a page table.
//
// Each instance is one node: a (cells + 1)² vertex grid whose vertices read exact samples of the
// node's height tile (textureLoad, no filtering), ringed by skirts: one more row of vertices on
// each side, hanging `skirt_m` below the edge. While a node's own tile streams in it reads its
// finest resident ancestor (at 1/2^k samples per cell); the skirts hide the seams that leaves
// against neighbours reading finer tiles, so a view is coarser there, never holed. Odd vertices morph onto the next coarser grid as
// the camera recedes (Strugar 2010), reaching it exactly at the node's outer range, so nodes of
// neighbouring LODs meet without cracks. Positions are camera-relative: the CPU subtracts in f64
// and hands small f32 offsets to the GPU. Imagery comes from the finest resident level at or
// above the one the pixel footprint asks for (a missing tile shows its ancestor, never a hole),
// sampled with explicit gradients taken from continuous grid-space coordinates, so tile edges
// cause no derivative spikes.

struct TerrainUniforms {
    clip_from_view_world: mat4x4<f32>,
    sun_dir: vec4<f32>,
    haze: vec4<f32>,
    camera_grid_m: vec4<f32>,
    height_range_m: vec2<f32>,
    node_cells: u32,
    has_imagery: u32,
    imagery_frame: vec4<f32>,
    imagery_levels: array<vec4<u32>, MAX_LEVELS>,
    imagery_level_count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct TerrainNode {
    origin_rel_m: vec2<f32>,
    cell_m: f32,
    height_slot: u32,
    sample_offset: vec2<f32>,
    morph_start_m: f32,
    morph_end_m: f32,
    cells_inside: vec2<f32>,
    sample_step: f32,
    skirt_m: f32,
}

@group(0) @binding(0) var<uniform> u: TerrainUniforms;
@group(0) @binding(1) var<storage, read> nodes: array<TerrainNode>;
@group(0) @binding(2) var height_tiles: texture_2d_array<f32>;
@group(0) @binding(3) var imagery_tiles: texture_2d_array<f32>;
@group(0) @binding(4) var imagery_sampler: sampler;
@group(0) @binding(5) var<storage, read> imagery_page_table: array<u32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    // Camera-relative position, metres.
    @location(0) rel_m: vec3<f32>,
    // Grid-space position (for imagery lookup), metres.
    @location(1) grid_m: vec2<f32>,
    @location(2) normal: vec3<f32>,
}

fn height_sample(node: TerrainNode, s: vec2<i32>) -> f32 {
    let limit = i32(HEIGHT_TILE_EXTENT) - 1;
    let at = clamp(s, vec2<i32>(0), vec2<i32>(limit));
    return textureLoad(height_tiles, at, i32(node.height_slot), 0).r;
}

// Height at grid position `g` of the node (fractional while morphing, or when reading an
// ancestor tile), bilinear between the tile's samples.
fn height_at(node: TerrainNode, g: vec2<f32>) -> f32 {
    let sample = node.sample_offset + g * node.sample_step;
    let base = floor(sample);
    let f = sample - base;
    let s = vec2<i32>(base);
    let h00 = height_sample(node, s);
    let h10 = height_sample(node, s + vec2<i32>(1, 0));
    let h01 = height_sample(node, s + vec2<i32>(0, 1));
    let h11 = height_sample(node, s + vec2<i32>(1, 1));
    return mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VertexOut {
    let node = nodes[instance];
    // The grid with its skirt ring: vertex (i, j) of (cells + 3)², the outer ring on the edges.
    let row = u.node_cells + 3u;
    let ij = vec2<f32>(f32(vertex % row), f32(vertex / row));
    let last = f32(u.node_cells + 2u);
    let skirt = ij.x == 0.0 || ij.y == 0.0 || ij.x == last || ij.y == last;
    let g = min(clamp(ij - 1.0, vec2<f32>(0.0), vec2<f32>(f32(u.node_cells))), node.cells_inside);

    let h = height_at(node, g) - u.camera_grid_m.z;
    let distance = length(vec3<f32>(node.origin_rel_m + g * node.cell_m, h));
    let morph = clamp((distance - node.morph_start_m) / (node.morph_end_m - node.morph_start_m), 0.0, 1.0);
    let g_morphed = min(g - fract(g * 0.5) * 2.0 * morph, node.cells_inside);

    let xy = node.origin_rel_m + g_morphed * node.cell_m;
    let z = height_at(node, g_morphed) - u.camera_grid_m.z - select(0.0, node.skirt_m, skirt);
    // Central differences one (level) sample apart; the tile border makes them valid at the edges.
    let dx = height_at(node, g_morphed + vec2<f32>(1.0, 0.0)) - height_at(node, g_morphed - vec2<f32>(1.0, 0.0));
    let dy = height_at(node, g_morphed + vec2<f32>(0.0, 1.0)) - height_at(node, g_morphed - vec2<f32>(0.0, 1.0));

    var out: VertexOut;
    out.rel_m = vec3<f32>(xy, z);
    out.clip = u.clip_from_view_world * vec4<f32>(out.rel_m, 1.0);
    out.grid_m = u.camera_grid_m.xy + xy;
    out.normal = normalize(vec3<f32>(-dx, -dy, 2.0 * node.cell_m));
    return out;
}

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

// Linear RGB, and in alpha the imagery's coverage (0 where the source had no data).
fn imagery_albedo(grid_m: vec2<f32>) -> vec4<f32> {
    // Level-0 texel coordinates, continuous across tiles: their derivatives are the footprint.
    let texel0 = (grid_m - u.imagery_frame.xy) / u.imagery_frame.z;
    let ddx0 = dpdx(texel0);
    let ddy0 = dpdy(texel0);
    let footprint = max(length(ddx0), length(ddy0));
    let wanted = log2(max(footprint, 1e-6)) + u.imagery_frame.w;
    let last = u.imagery_level_count - 1u;
    var level = u32(clamp(floor(wanted), 0.0, f32(last)));
    var slot = 0u;
    loop {
        let info = u.imagery_levels[level];
        let tile = clamp(vec2<i32>(floor(texel0 / f32(1u << level) / f32(IMAGERY_TILE_TEXELS))),
                         vec2<i32>(0), vec2<i32>(info.yz) - 1);
        slot = imagery_page_table[info.x + u32(tile.y) * info.y + u32(tile.x)];
        if slot != 0u || level >= last {
            break;
        }
        level += 1u;
    }
    if slot == 0u {
        return vec4<f32>(0.0);
    }
    let info = u.imagery_levels[level];
    let scale = 1.0 / f32(1u << level);
    let texel = texel0 * scale;
    let tile = clamp(floor(texel / f32(IMAGERY_TILE_TEXELS)), vec2<f32>(0.0), vec2<f32>(info.yz) - 1.0);
    let extent = f32(IMAGERY_TILE_EXTENT);
    let uv = (texel - tile * f32(IMAGERY_TILE_TEXELS) + f32(IMAGERY_BORDER)) / extent;
    // The cache is an sRGB texture: filtering happens on linear values, as it should.
    let colour = textureSampleGrad(imagery_tiles, imagery_sampler, uv, i32(slot - 1u),
                                   ddx0 * scale / extent, ddy0 * scale / extent);
    return colour;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let normal = normalize(in.normal);
    let height_m = in.rel_m.z + u.camera_grid_m.z;
    var albedo = tint(height_m, normal);
    if u.has_imagery != 0u {
        // Where the imagery has no data (or no tile is resident yet), the relief tint shows.
        let imagery = imagery_albedo(in.grid_m);
        albedo = mix(albedo, imagery.rgb, imagery.a);
    }
    let sun = max(dot(normal, u.sun_dir.xyz), 0.0);
    let sky = 0.35 * (0.5 + 0.5 * normal.z);
    let lit = albedo * (sun * 0.9 + sky);
    let haze = 1.0 - exp2(-length(in.rel_m) / u.haze.w);
    // The target is sRGB: the hardware encodes on store.
    return vec4<f32>(mix(lit, u.haze.rgb, haze), 1.0);
}
