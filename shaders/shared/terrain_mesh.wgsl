// The terrain mesh, shared by the terrain (depth) and ground (shading) passes: CDLOD nodes
// displaced by height tiles.
//
// Each instance is one node: a (cells + 1)² vertex grid whose vertices read exact samples of the
// node's height tile (textureLoad, no filtering), ringed by skirts: one more row of vertices on
// each side, hanging `skirt_m` below the edge. Odd vertices morph onto the next coarser grid as
// the camera recedes (Strugar 2010), reaching it exactly at the node's outer range, so nodes of
// neighbouring LODs meet without cracks. While a node's own tile streams in it reads its finest
// resident ancestor (at 1/2^k samples per cell); the skirts hide the seams that leaves against
// neighbours reading finer tiles, so the view is coarser there, never holed. The grid is laid out
// on the flat sheet (the morph, the heights, the normals); each vertex is then placed by its
// node's Earth mapping (`shared/earth.wgsl`, origin the node's centre at height 0: on the ellipsoid
// from the camera's frame, or the identity on a flat dataset), camera-relative: the CPU subtracts
// in f64 and hands small f32 offsets to the GPU. Both passes compute positions with this same code
// and `@invariant`, so the ground pass can shade exactly the fragments the depth pass kept.

struct TerrainUniforms {
    clip_from_view_world: mat4x4<f32>,
    sun_dir: vec4<f32>,
    camera_grid_m: vec4<f32>,
    height_range_m: vec2<f32>,
    node_cells: u32,
    imagery_texels: u32,
    imagery_frame: vec4<f32>,
    cloud_field: vec4<f32>,
    cloud_shift: vec4<f32>,
    imagery_levels: array<vec4<u32>, MAX_LEVELS>,
    imagery_level_count: u32,
    _pad: u32,
    vegetation: vec2<f32>,
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
// Each node's Earth mapping, by the node's index.
@group(0) @binding(6) var<storage, read> node_earth: array<EarthNode>;

struct VertexOut {
    @builtin(position) @invariant clip: vec4<f32>,
    // Camera-relative position, metres.
    @location(0) rel_m: vec3<f32>,
    // Grid-space position (for imagery lookup), metres.
    @location(1) grid_m: vec2<f32>,
    @location(2) normal: vec3<f32>,
    // The ground's height above the datum, metres.
    @location(3) height_m: f32,
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

// A vertex of the drawn surface on the flat sheet: node grid position `g`, morphed as the camera
// recedes.
struct SurfaceVertex {
    // Camera-relative horizontal position on the flat sheet and the ground's height under it less
    // the camera's, metres.
    xy: vec2<f32>,
    z: f32,
    // The flat sheet's normal.
    normal: vec3<f32>,
    // The (morphed) grid offset from the node's south-west corner, and the ground's height, metres.
    offset_m: vec2<f32>,
    height_m: f32,
}

fn surface_vertex(node: TerrainNode, g: vec2<f32>) -> SurfaceVertex {
    let h = height_at(node, g) - u.camera_grid_m.z;
    let distance = length(vec3<f32>(node.origin_rel_m + g * node.cell_m, h));
    let morph = clamp((distance - node.morph_start_m) / (node.morph_end_m - node.morph_start_m), 0.0, 1.0);
    let g_morphed = min(g - fract(g * 0.5) * 2.0 * morph, node.cells_inside);
    // Central differences one (level) sample apart; the tile border makes them valid at the edges.
    let dx = height_at(node, g_morphed + vec2<f32>(1.0, 0.0)) - height_at(node, g_morphed - vec2<f32>(1.0, 0.0));
    let dy = height_at(node, g_morphed + vec2<f32>(0.0, 1.0)) - height_at(node, g_morphed - vec2<f32>(0.0, 1.0));
    let offset_m = g_morphed * node.cell_m;
    let height_m = height_at(node, g_morphed);
    return SurfaceVertex(
        node.origin_rel_m + offset_m,
        height_m - u.camera_grid_m.z,
        normalize(vec3<f32>(-dx, -dy, 2.0 * node.cell_m)),
        offset_m,
        height_m,
    );
}

// Where node `index` draws the point at grid offset `offset_m` from its south-west corner,
// `height_m` above the datum: camera-relative, on the Earth.
fn placed_m(index: u32, offset_m: vec2<f32>, height_m: f32) -> vec3<f32> {
    return earth_position_m(node_earth[index], from_mapping_origin_m(index, offset_m, height_m));
}

// The drawn surface's unit normal there, of the flat sheet's `normal`.
fn placed_normal(index: u32, offset_m: vec2<f32>, height_m: f32, normal: vec3<f32>) -> vec3<f32> {
    return normalize(earth_normal(node_earth[index], from_mapping_origin_m(index, offset_m, height_m), normal));
}

// That point's offset from the origin of node `index`'s mapping: the node's centre at height 0.
fn from_mapping_origin_m(index: u32, offset_m: vec2<f32>, height_m: f32) -> vec3<f32> {
    let centre_m = vec2<f32>(0.5 * f32(u.node_cells) * nodes[index].cell_m);
    return vec3<f32>(offset_m - centre_m, height_m);
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
    let surface = surface_vertex(node, g);
    // Skirts hang `skirt_m` below the edge, but never lower than a cell under the dataset's lowest
    // ground: still below both sides of any seam, and nothing dangles under the terrain for a view
    // past its edge to see.
    let floor_m = u.height_range_m.x - node.cell_m;
    let height_m = select(surface.height_m, max(surface.height_m - node.skirt_m, floor_m), skirt);

    var out: VertexOut;
    out.rel_m = placed_m(instance, surface.offset_m, height_m);
    out.clip = u.clip_from_view_world * vec4<f32>(out.rel_m, 1.0);
    out.grid_m = u.camera_grid_m.xy + surface.xy;
    out.normal = placed_normal(instance, surface.offset_m, surface.height_m, surface.normal);
    out.height_m = surface.height_m;
    return out;
}
