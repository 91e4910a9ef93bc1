// The texcell pass: the far forest as slices of a baked forest sample (Decaudin & Neyret 2004)
// over the terrain mesh (`shared/terrain_mesh.wgsl`, group 0 the terrain's bindings).
//
// Each instance is one slice of one patch (a quadrant of a terrain node the frame draws): the
// quadrant's grid, morphed exactly as the ground, lifted by the slice's height in the slab. A
// fragment finds its forest sample from the land cover under it (a bilinear blend of the four
// nearest level-1 classes' "dense" flags, so forest edges follow the classification smoothly),
// its tile from the aperiodic tiling of the ground (a cell's lower or upper triangle, the edge
// colours hashed from the lattice's vertices: Rust `texcell::tiling`), and reads that tile's texel
// of its slice in the slice pyramid level the patch draws, at that level's mip or coarser. The
// texel is premultiplied coverage; its opacity is corrected for the oblique path between slices
// (A' = 1 − (1 − A)^k, k = 1 / cos of the view to the ground's normal, clamped), its colour made
// to follow the photograph under it (a ratio transfer, `shade`), lit and seen through the air like the ground,
// and it fades in
// (dithered) where the last billboard clouds fade out, and out before the reach.
//
// Where the view grazes the canopy a patch also draws a silhouette instance (Decaudin & Neyret
// § 6): the slab's top face, each fragment of which samples the 3D texture where its ray crosses
// the paper's camera-facing slices (planes across the view, a fixed spacing apart from the
// node's origin, so they stay put as the eye moves), one voxel of the 3D mip level the pixel
// needs apart (the paper's slicing rate), from the top to the ground or out of the slab again,
// composited front to back. The two kinds share a patch's pixels by an ordered dither on how
// steeply the pixel's ray descends.

struct TexcellUniforms {
    lcc_levels: array<vec4<u32>, 4>,
    lcc_size: vec2<u32>,
    lcc_sub_bits: u32,
    lcc_level: u32,
    lcc_frame: vec4<f32>,
    fade_m: vec4<f32>,
    slab_height_m: f32,
    inv_cell_m: f32,
    seed: u32,
    tile_cells: u32,
    texels: f32,
    finest_slices: u32,
    opacity_max_factor: f32,
    ground_blend: f32,
    silhouette_sin: vec2<f32>,
    metres_per_px_at_1m: f32,
    silhouette_steps: u32,
    sample_count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    sample_albedo: array<vec4<f32>, TEXCELL_MAX_SAMPLES>,
}

struct TexcellRecord {
    node: u32,
    slice: u32,
}

@group(1) @binding(0) var<uniform> tu: TexcellUniforms;
@group(1) @binding(1) var<storage, read> texcell_records: array<TexcellRecord>;
@group(1) @binding(2) var forest_slices: texture_2d_array<f32>;
@group(1) @binding(3) var forest_sampler: sampler;
@group(1) @binding(4) var<storage, read> sample_of_class: array<u32>;
@group(1) @binding(5) var<storage, read> lcc_page_table: array<u32>;
@group(1) @binding(6) var lcc_tiles: texture_2d_array<u32>;
@group(1) @binding(7) var forest_volume: texture_3d<f32>;

struct TexcellOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) rel_m: vec3<f32>,
    @location(1) grid_m: vec2<f32>,
    @location(2) normal: vec3<f32>,
    // The slice (its index among the finest slices: the texture layer within a sample) and the
    // slice pyramid level: the coarsest mip it may read.
    @location(3) @interpolate(flat) slice: vec2<u32>,
    // The record's kind (`TEXCELL_REGULAR`, ...) and its terrain node.
    @location(4) @interpolate(flat) kind_node: vec2<u32>,
    // The position on the flat sheet (the silhouettes march their node's ground there), and the
    // ground's height under it above the datum, metres.
    @location(5) flat_rel_m: vec3<f32>,
    @location(6) height_m: f32,
}

@vertex
fn vs_texcell(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> TexcellOut {
    let record = texcell_records[instance];
    let s = unpack_texcell_slice(record.slice);
    let node = nodes[record.node];
    // The quadrant's grid: vertex (i, j) of (cells / 2 + 1)², offset to the quadrant.
    let half = u.node_cells / 2u;
    let row = half + 1u;
    let quadrant = vec2<f32>(f32(s.quadrant & 1u), f32(s.quadrant >> 1u)) * f32(half);
    let g = min(quadrant + vec2<f32>(f32(vertex % row), f32(vertex / row)), node.cells_inside);
    let surface = surface_vertex(node, g);
    let slices = tu.finest_slices >> s.level;
    var lift = (f32(s.index) + 0.5) / f32(slices) * tu.slab_height_m;
    if s.kind == TEXCELL_SILHOUETTE {
        lift = tu.slab_height_m;
    }

    var out: TexcellOut;
    // Lifted along the ground's vertical: on the Earth, the node's up.
    out.rel_m = placed_m(record.node, surface.offset_m, surface.height_m + lift);
    out.clip = u.clip_from_view_world * vec4<f32>(out.rel_m, 1.0);
    out.grid_m = u.camera_grid_m.xy + surface.xy;
    out.normal = placed_normal(record.node, surface.offset_m, surface.height_m, surface.normal);
    out.flat_rel_m = vec3<f32>(surface.xy, surface.z + lift);
    out.height_m = surface.height_m;
    out.slice = vec2<u32>(s.index << s.level, s.level);
    out.kind_node = vec2<u32>(s.kind, record.node);
    return out;
}

// --- The aperiodic tiling (Rust: `texcell::tiling`) ---

fn lattice_colour(i: i32, j: i32) -> u32 {
    return pcg(pcg(pcg(bitcast<u32>(i) ^ 0x7e3ca1f5u) ^ (bitcast<u32>(j) * 0x9e3779b9u)) ^ tu.seed) >> 31u;
}

fn horizontal_edge(i: i32, j: i32) -> u32 {
    return lattice_colour(i, j) ^ lattice_colour(i + 1, j) ^ (bitcast<u32>(j) & 1u);
}

fn vertical_edge(i: i32, j: i32) -> u32 {
    return lattice_colour(i, j) ^ lattice_colour(i, j + 1);
}

// Where grid position `grid_m` reads the forest sample, in sample units (the sample wraps at 1):
// the sample's triangle of the same half and edge colours as the ground's triangle there.
fn forest_uv(grid_m: vec2<f32>) -> vec2<f32> {
    let p = grid_m * tu.inv_cell_m;
    let cell = floor(p);
    let f = p - cell;
    let c = vec2<i32>(cell);
    let bottom = horizontal_edge(c.x, c.y);
    let right = vertical_edge(c.x + 1, c.y);
    let diagonal = bottom ^ right;
    var entry = 0u;
    if f.x > f.y {
        entry = bottom | (right << 1u) | (diagonal << 2u);
    } else {
        entry = 8u + (horizontal_edge(c.x, c.y + 1) | (vertical_edge(c.x, c.y) << 1u) | (diagonal << 2u));
    }
    let sample_cell = (tu.tile_cells >> (2u * entry)) & 3u;
    return (vec2<f32>(f32(sample_cell & 1u), f32(sample_cell >> 1u)) + f) * (1.0 / f32(TEXCELL_REFERENCE_CELLS));
}

// --- The forest under a fragment ---

struct Forest {
    // Index of the forest sample (the class's), and how much of the point is that forest (0 to 1).
    sample: u32,
    coverage: f32,
}

// The dense classes around `grid_m`: the four nearest level-1 texels, weighted bilinearly; the
// sample of the heaviest.
fn forest_at(grid_m: vec2<f32>) -> Forest {
    let t = (grid_m - tu.lcc_frame.xy) * tu.lcc_frame.z - 0.5;
    let base = floor(t);
    let f = t - base;
    var best = Forest(0u, 0.0);
    var best_weight = 0.0;
    var coverage = 0.0;
    for (var k = 0u; k < 4u; k += 1u) {
        let offset = vec2<f32>(f32(k & 1u), f32(k >> 1u));
        let q = vec2<u32>(clamp(base + offset, vec2<f32>(0.0), vec2<f32>(tu.lcc_size) - 1.0));
        let palette = landcover_class(q, tu.lcc_level, tu.lcc_levels, tu.lcc_sub_bits).x;
        if palette >= arrayLength(&sample_of_class) {
            continue;
        }
        let sample = sample_of_class[palette];
        if sample == 0u {
            continue;
        }
        let w = mix(1.0 - f.x, f.x, offset.x) * mix(1.0 - f.y, f.y, offset.y);
        coverage += w;
        if w > best_weight {
            best_weight = w;
            best.sample = sample - 1u;
        }
    }
    best.coverage = coverage;
    return best;
}

@fragment
fn fs_texcell(in: TexcellOut) -> @location(0) vec4<f32> {
    // Derivatives first, in uniform control flow: the mip from the continuous texel coordinate
    // (the tiling's jumps between tiles would spike it), the imagery's from the grid position.
    let texel = in.grid_m * (tu.inv_cell_m / f32(TEXCELL_REFERENCE_CELLS) * tu.texels);
    let footprint = max(length(dpdx(texel)), length(dpdy(texel)));
    let normal = normalize(in.normal);
    let photo = imagery_sample(in.grid_m);
    let ground = ground_albedo(imagery_coverage(photo), in.height_m, normal);
    // Where the photograph's vegetation index says bare ground, the forest thins out.
    let growth = vegetation_growth(photo);

    let distance_m = length(in.rel_m);
    let fade = clamp((distance_m - tu.fade_m.x) / tu.fade_m.y, 0.0, 1.0)
        * clamp((tu.fade_m.z + tu.fade_m.w - distance_m) / tu.fade_m.w, 0.0, 1.0);
    let view = normalize(in.rel_m);
    let pixel = vec2<u32>(in.clip.xy);
    // The share of a patch's pixels its regular slices keep: all of them unless it has a
    // silhouette too; then from none where the view grazes to all where it is steep enough.
    var regular = 1.0;
    if in.kind_node.x != TEXCELL_REGULAR {
        let sin_e = -view.z;
        regular = clamp((sin_e - tu.silhouette_sin.x) / (tu.silhouette_sin.y - tu.silhouette_sin.x), 0.0, 1.0);
    }
    if bayer4(pixel, 0u) >= fade {
        discard;
    }
    if in.kind_node.x == TEXCELL_SILHOUETTE {
        if bayer4(pixel, 5u) < regular {
            discard;
        }
        return silhouette(in.flat_rel_m, in.kind_node.y, view, distance_m, ground) * growth;
    }
    let forest = forest_at(in.grid_m);
    if forest.coverage <= 0.0 || bayer4(pixel, 5u) >= regular {
        discard;
    }
    let lod = max(log2(max(footprint, 1e-6)), f32(in.slice.y));
    let layer = i32(forest.sample * tu.finest_slices + in.slice.x);
    let sampled = textureSampleLevel(forest_slices, forest_sampler, forest_uv(in.grid_m), layer, lod);
    let alpha = sampled.a * forest.coverage * growth;
    if alpha <= 0.0 {
        discard;
    }
    // The path between two slices, seen along the view, is 1 / cos longer than straight through.
    let path = min(normal.z / max(abs(dot(normal, view)), 1e-4), tu.opacity_max_factor);
    let corrected = 1.0 - pow(1.0 - min(alpha, 0.9999), max(path, 0.25));

    let surface = Surface(sampled.rgb / max(sampled.a, 1e-4), tu.sample_albedo[forest.sample].rgb, normal);
    return shade(surface, ground, in.rel_m, view, distance_m, corrected);
}

// What a texcell fragment shows: the forest's albedo there, its sample's mean albedo seen from
// above, and the ground's normal under it.
struct Surface {
    albedo: vec3<f32>,
    sample_mean: vec3<f32>,
    normal: vec3<f32>,
}

// The premultiplied colour of forest `surface` of opacity `opacity` at `rel_m` from the camera,
// seen along `view`, `distance_m` away (seen through the air between, `through_air`), over
// ground of albedo `ground` (`ground_albedo`: the photograph, or the relief tint where it has
// no data, as the ground pass shows). In its own colours it is lit as the seeds' leaves are on average: the leaves the eye sees face it (the seeds turn
// every surface towards the eye), their normals spread over the half of directions facing it,
// whose mean clamped cosine towards the sun is (1 + cos(eye, sun)) / 4. The colour follow-up (a
// ratio transfer, as the seeds'), by `ground_blend`: the albedo times the photograph's colour over
// the sample's mean seen from above, lit as the ground under it is (its normal, the sun through
// the clouds, the sky), so that followed fully its mean from above is the ground's own frame and
// each texel keeps its contrast, until, seen from above, a pixel spans a crown
// (`TEXCELL_DETAIL_*`): there the followed forest has nothing left to add to the photograph, which
// already shows it, and fades out (its slab's parallax would only shift the photograph).
fn shade(surface: Surface, ground: vec3<f32>, rel_m: vec3<f32>, view: vec3<f32>, distance_m: f32, coverage: f32) -> vec4<f32> {
    let clouds = sun_through_clouds(u.cloud_field, u.cloud_shift, rel_m);
    let light = light_at(rel_m);
    let sun = u.sun_dir.xyz;
    let facing = 0.25 * (1.0 - dot(view, sun));
    let own_sun = (FOLIAGE_SUN * facing + FOLIAGE_SUN_WRAP * max(dot(light.up, sun), 0.0)) * clouds;
    let own = surface.albedo * (light.sun * own_sun + light.sky * FOLIAGE_SKY);
    var lit = own;
    var opacity = coverage;
    if u.imagery_texels != IMAGERY_NONE && all(surface.sample_mean > vec3<f32>(0.0)) {
        let n = surface.normal;
        let ground_light = light.sun * max(dot(n, sun), 0.0) * clouds + light.sky * (0.5 + 0.5 * dot(n, light.up));
        let followed = ground * surface.albedo / surface.sample_mean * ground_light;
        lit = mix(own, followed, tu.ground_blend);
        let px_m = distance_m * tu.metres_per_px_at_1m;
        let from_above = smoothstep(PHOTO_DETAIL_GRAZING_SIN, PHOTO_DETAIL_STEEP_SIN, -view.z);
        let flat = smoothstep(TEXCELL_DETAIL_FULL_PX_M, TEXCELL_DETAIL_NONE_PX_M, px_m) * from_above;
        opacity *= 1.0 - flat * tu.ground_blend;
    }
    return vec4<f32>(through_air(lit, rel_m) * opacity, opacity);
}

// A silhouette texcell's fragment on the slab's top: its ray through the 3D texture, sampled where
// it crosses the camera-facing slices, front to back, until it reaches the ground, leaves the slab
// or is opaque. The first half of `silhouette_steps` are one voxel of the 3D level the pixel's cone
// needs apart (the paper's slicing rate: where the ray enters the canopy, which draws the skyline);
// the rest grow apart evenly so that all of them span the ray's path through a flat slab
// (slab / sin of the ray's descent), each read at the level its spacing needs. The ray is
// marched on the flat sheet, from the fragment's place there (`flat_rel_m`) along the view turned
// into the node's own frame: within a slab the Earth's bend is far below a voxel.
fn silhouette(flat_rel_m: vec3<f32>, node_index: u32, camera_view: vec3<f32>, distance_m: f32, ground: vec3<f32>) -> vec4<f32> {
    let node = nodes[node_index];
    let view = normalize(earth_flat_direction(node_earth[node_index], camera_view));
    let slab_m = tu.slab_height_m;
    let texel_m = f32(TEXCELL_REFERENCE_CELLS) / (tu.inv_cell_m * tu.texels);
    let slice_m = slab_m / f32(tu.finest_slices);
    let coarsest = log2(f32(tu.finest_slices));
    let base_m = max(distance_m * tu.metres_per_px_at_1m, texel_m);
    let even = tu.silhouette_steps / 2u;
    let growing = f32(tu.silhouette_steps - even);
    let rest_m = slab_m / max(-view.z, 1e-3) - f32(even) * base_m;
    let growth = max(0.0, (rest_m / base_m - growing) * 2.0 / (growing * (growing + 1.0)));
    // The slices lie at odd multiples of half a base step along the view from the node's origin,
    // so they stay put as the eye moves.
    let origin = vec3<f32>(node.origin_rel_m, -u.camera_grid_m.z);
    let along = dot(flat_rel_m - origin, view);
    var t = (ceil(along / base_m - 0.5) + 0.5) * base_m - along;

    var colour = vec3<f32>(0.0);
    var sample_mean = vec3<f32>(0.0);
    var transmit = 1.0;
    var entered = false;
    var hit_m = distance_m;
    for (var k = 0u; k < tu.silhouette_steps; k += 1u) {
        let step_m = base_m * (1.0 + growth * f32(max(k + 1u, even) - even));
        let p = flat_rel_m + view * t;
        let p_along_m = t;
        t += step_m;
        let above_m = p.z - (height_at(node, (p.xy - node.origin_rel_m) / node.cell_m) - u.camera_grid_m.z);
        if above_m < 0.0 {
            break;
        }
        if above_m > slab_m {
            if entered {
                break;
            }
            continue;
        }
        entered = true;
        let grid = u.camera_grid_m.xy + p.xy;
        let forest = forest_at(grid);
        if forest.coverage <= 0.0 {
            continue;
        }
        // The level whose voxels are as tall as the step: the canopy's relief is vertical, and
        // the volume has far fewer texels up than across (a finer level across than the cone
        // needs only sharpens the crowns a ray passes).
        let lod = clamp(log2(step_m / slice_m), 0.0, coarsest);
        // The depth coordinate stays half a texel of the coarser level read inside this sample.
        let margin = 0.5 / max(f32(tu.finest_slices) / exp2(ceil(lod)), 1.0);
        let w = (f32(forest.sample) + clamp(above_m / slab_m, margin, 1.0 - margin)) / f32(tu.sample_count);
        let voxel = textureSampleLevel(forest_volume, forest_sampler, vec3<f32>(forest_uv(grid), w), lod);
        let a = voxel.a * forest.coverage;
        if a <= 0.0 {
            continue;
        }
        // A voxel's opacity is the slice's: through `slice_m` of canopy; the ray crosses `step_m`.
        let alpha = 1.0 - pow(1.0 - min(a, 0.9999), step_m / slice_m);
        if transmit == 1.0 {
            hit_m = distance_m + p_along_m;
            sample_mean = tu.sample_albedo[forest.sample].rgb;
        }
        colour += transmit * alpha * (voxel.rgb / max(voxel.a, 1e-4));
        transmit *= 1.0 - alpha;
        if transmit < 0.01 {
            break;
        }
    }
    let opacity = 1.0 - transmit;
    if opacity <= 0.0 {
        discard;
    }
    // Shaded where the ray first met the canopy, and seen through the air from there.
    // The forest's colour follows the photograph by the first sample the ray met; the ground's
    // normal is taken as up (the ray crosses the slab, not one point of the ground).
    let surface = Surface(colour / opacity, sample_mean, vec3<f32>(0.0, 0.0, 1.0));
    return shade(surface, ground, camera_view * hit_m, camera_view, hit_m, opacity);
}

// --- For the test that holds `forest_uv` equal to its twin (`passes::texcells::gpu::probe`) ---

@group(2) @binding(0) var<storage, read> probe_points: array<vec2<f32>>;
@group(2) @binding(1) var<storage, read_write> probe_uvs: array<vec2<f32>>;

@compute @workgroup_size(TEXCELL_PROBE_WORKGROUP)
fn probe_forest_uv(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < arrayLength(&probe_points) {
        probe_uvs[id.x] = forest_uv(probe_points[id.x]);
    }
}
