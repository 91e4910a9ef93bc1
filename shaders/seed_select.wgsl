// Pass 3, seed selection (Amara et al. 2007, § 4.4): one invocation per seed of each active
// ring-0 cell's pattern (workgroups along x cover a pattern, one row of workgroups per cell).
// A seed is placed on the finest resident height level (on the ground that level's mesh draws,
// `shared/terrain_surface.wgsl`: identical whatever the mesh LOD), given a class by the LCC
// quadtree (any resident level: the coding makes them agree), a species by its rank, checked
// against its species' altitude and slope rules, sized by its hash, cut at the radial LOD distance
// for its size, culled by frustum (bounding sphere, NDC tolerance) and by occlusion (its summit
// against the terrain's depth, with a tolerance growing with distance), both bounds grown by the
// wind's reach for plants, and written out with its ground colour from the imagery around it.
//
// Exactness: the CPU twin (`reference/seed_select.rs`) must take the same decisions, so the
// shader avoids division and transcendental functions, and every product goes through `mul`,
// which no compiler can fuse into an FMA. Large coordinates never reach f32: each cell's corner
// comes as an integer texel plus a remainder in every layer's own grid.
//
// The occlusion march is `seed_select_march.wgsl`. The output (`seed_select_blocks.wgsl`): a
// workgroup numbers its survivors by a ballot (rank order, every run), claims room with one global
// atomic (where it lands varies), writes them with their draw-group keys, and notes where in its
// fixed block-table entry: read in table order, records come in the twin's order (compaction keeps
// it). When the records overflow `capacity`, `settle` renumbers the table in table order and the
// blocks that keep anything select again into their new places, so the first `capacity` records in
// the twin's order are kept, on every run.

struct SeedUniforms {
    clip_from_view_world: mat4x4<f32>,
    camera_z_m: f32,
    near_m: f32,
    frustum_epsilon: f32,
    no_fuse: u32,
    clip_row_len: vec2<f32>,
    screen_px: vec2<u32>,
    occlusion_tolerance_m: f32,
    occlusion_tolerance_per_m: f32,
    inv_reference_height_m: f32,
    sink_fraction: f32,
    draw_reach_m: vec4<f32>,
    cell_in_samples: f32,
    cell_in_lcc_texels: f32,
    cell_in_imagery_texels: f32,
    ground_radius_texels: f32,
    inv_spacing_m: f32,
    seeds_per_pattern: u32,
    capacity: u32,
    seed: u32,
    height_size: vec2<u32>,
    height_level_count: u32,
    lcc_sub_bits: u32,
    lcc_size: vec2<u32>,
    imagery_level_count: u32,
    cell_m: f32,
    imagery_size: vec2<u32>,
    ndc_per_px: vec2<f32>,
    camera_sample: vec2<i32>,
    camera_sample_frac: vec2<f32>,
    refine_max_steps: u32,
    active_ranks: u32,
    wind_reach_per_height: f32,
    cell_count: u32,
    height_levels: array<vec4<u32>, MAX_LEVELS>,
    lcc_levels: array<vec4<u32>, 4>,
    imagery_levels: array<vec4<u32>, MAX_LEVELS>,
    vegetation: vec4<f32>,
    class_edge_dither: u32,
    chord_sag_per_m2: f32,
    _pad0: u32,
    _pad1: u32,
}

struct SeedCell {
    rel_m: vec2<f32>,
    address: vec2<i32>,
    height_sample: vec2<i32>,
    height_frac: vec2<f32>,
    lcc_texel: vec2<i32>,
    lcc_frac: vec2<f32>,
    imagery_texel: vec2<i32>,
    imagery_frac: vec2<f32>,
    pattern: u32,
    lcc_level: u32,
    _pad: vec2<u32>,
    earth: EarthNode,
}

struct SeedSpecies {
    height_m: vec2<f32>,
    altitude_m: vec2<f32>,
    max_slope_tan_sq: f32,
    radius_per_height: f32,
    kind: u32,
    wind_bend: f32,
    variants: u32,
    _pad: u32,
}

struct SeedClass {
    rank_limit: vec4<f32>,
    species: vec4<u32>,
    lods: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

struct SeedCounters {
    count: array<atomic<u32>, SEED_COUNTERS>,
}

// Per-frame constants in a storage buffer, not a uniform buffer: see tile_load_map.wgsl.
@group(0) @binding(0) var<storage, read> u: SeedUniforms;
@group(0) @binding(1) var<storage, read> cells: array<SeedCell>;
@group(0) @binding(2) var<storage, read> patterns: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read> species_table: array<SeedSpecies>;
@group(0) @binding(4) var<storage, read> class_table: array<SeedClass>;
@group(0) @binding(5) var<storage, read> height_page_table: array<u32>;
@group(0) @binding(6) var height_tiles: texture_2d_array<f32>;
@group(0) @binding(7) var<storage, read> lcc_page_table: array<u32>;
@group(0) @binding(8) var lcc_tiles: texture_2d_array<u32>;
@group(0) @binding(9) var<storage, read> imagery_page_table: array<u32>;
@group(0) @binding(10) var imagery_tiles: texture_2d_array<f32>;
@group(0) @binding(11) var depth: texture_depth_2d;
@group(0) @binding(12) var<storage, read_write> records: array<SeedRecord>;
@group(0) @binding(13) var<storage, read_write> counters: SeedCounters;
@group(0) @binding(14) var<storage, read_write> keys: array<u32>;
@group(0) @binding(15) var<storage, read_write> blocks: array<SeedBlock>;
@group(0) @binding(16) var<storage, read> height_tile_max_m: array<f32>;
@group(0) @binding(17) var<storage, read> height_block_max_m: array<f32>;

// a · b, correctly rounded and never fused into a following add.
fn mul(a: f32, b: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(a * b) | u.no_fuse);
}

fn seed_hash(address: vec2<i32>, rank: u32) -> u32 {
    return pcg(rank ^ pattern_hash(bitcast<u32>(address.x), bitcast<u32>(address.y), u.seed ^ SEED_SALT));
}

// Which of its species' `variants` models a seed of hash `hash` is (Rust: `seeds::seed_variant`).
fn seed_variant(hash: u32, variants: u32) -> u32 {
    return pcg(hash ^ SEED_VARIANT_SALT) % max(variants, 1u);
}

fn unit(hash: u32) -> f32 {
    return f32(hash >> 8u) * (1.0 / 16777216.0);
}

// A position in a layer's texel grid: integer texel and remainder in [0, 1).
struct GridPos {
    texel: vec2<i32>,
    frac: vec2<f32>,
}

fn grid_pos(corner: vec2<i32>, corner_frac: vec2<f32>, pos_unit: vec2<f32>, cell_in_texels: f32) -> GridPos {
    let t = corner_frac + vec2<f32>(mul(pos_unit.x, cell_in_texels), mul(pos_unit.y, cell_in_texels));
    let whole = floor(t);
    return GridPos(corner + vec2<i32>(whole), t - whole);
}

fn mul3(v: vec3<f32>, s: f32) -> vec3<f32> {
    return vec3<f32>(mul(v.x, s), mul(v.y, s), mul(v.z, s));
}

// Where the point at grid offset `offset_m.xy` from `e`'s origin (a cell's corner) and height
// `offset_m.z` stands, camera-relative: `earth_position_m` (`shared/earth.wgsl`), product by
// product. Flat: the corner's offset from the camera plus the point's, the height less the
// camera's.
fn placed_m(e: EarthNode, offset_m: vec3<f32>) -> vec3<f32> {
    let dx = offset_m.x;
    let dy = offset_m.y;
    let dh = offset_m.z;
    let curved = mul3(e.d_xx.xyz, mul(dx, dx)) + mul3(e.d_xy.xyz, mul(dx, dy)) + mul3(e.d_yy.xyz, mul(dy, dy));
    let turned = mul3(mul3(e.d_xh.xyz, dx) + mul3(e.d_yh.xyz, dy), dh);
    let linear = mul3(e.d_x.xyz, dx) + mul3(e.d_y.xyz, dy) + mul3(e.d_h.xyz, dh);
    return e.origin_m.xyz + (linear + (curved + turned));
}

// The local vertical (not unit: within 1e-6 of it) at grid offset `offset_m` from `e`'s origin:
// the mapping's ∂p/∂h there. Straight up on the flat sheet.
fn up_at(e: EarthNode, offset_m: vec2<f32>) -> vec3<f32> {
    return e.d_h.xyz + mul3(e.d_xh.xyz, offset_m.x) + mul3(e.d_yh.xyz, offset_m.y);
}

// Clip position of camera-relative `p`, product by product.
fn to_clip(p: vec3<f32>) -> vec4<f32> {
    let m = u.clip_from_view_world;
    var clip: vec4<f32>;
    for (var r = 0; r < 4; r += 1) {
        clip[r] = mul(m[0][r], p.x) + mul(m[1][r], p.y) + mul(m[2][r], p.z) + m[3][r];
    }
    return clip;
}

struct Ground {
    height_m: f32,
    // Height change per metre east and north.
    gradient: vec2<f32>,
    level: u32,
    found: bool,
}

// The level-`level` height tile holding level-0 sample `s0` (x, y), and its page-table index (z).
fn height_tile_at(s0: vec2<u32>, level: u32) -> vec3<u32> {
    let info = u.height_levels[level];
    let tile = min((s0 >> vec2<u32>(level)) / HEIGHT_TILE_CELLS, info.yz - 1u);
    return vec3<u32>(tile, info.x + tile.y * info.y + tile.x);
}

// The tile the drawn ground at level-0 sample `s0` comes from: the finest level whose tile there
// is resident (slot PAGE_EMPTY when none is, at the coarsest level).
struct HeightTile {
    level: u32,
    tile: vec2<u32>,
    slot: u32,
}

fn height_tile(s0: vec2<u32>) -> HeightTile {
    var level = 0u;
    loop {
        let at = height_tile_at(s0, level);
        let slot = height_page_table[at.z];
        if slot != PAGE_EMPTY || level + 1u >= u.height_level_count {
            return HeightTile(level, at.xy, slot);
        }
        level += 1u;
    }
    return HeightTile(0u, vec2<u32>(0u), PAGE_EMPTY);
}

// The drawn ground at `p` (level-0 samples) from the finest resident level: its cell split as that
// level's mesh splits it.
fn ground_at(p: GridPos) -> Ground {
    return ground_in(height_tile(vec2<u32>(p.texel)), p);
}

// The drawn ground at `p` from `hit`, `p`'s `height_tile`.
fn ground_in(hit: HeightTile, p: GridPos) -> Ground {
    let level = hit.level;
    if hit.slot == PAGE_EMPTY {
        return Ground(0.0, vec2<f32>(0.0), level, false);
    }
    let s0 = vec2<u32>(p.texel);
    let s = s0 >> vec2<u32>(level);
    let local = vec2<i32>(s - hit.tile * HEIGHT_TILE_CELLS + HEIGHT_BORDER);
    let layer = page_layer(hit.slot);
    let h00 = textureLoad(height_tiles, local, layer, 0).r;
    let h10 = textureLoad(height_tiles, local + vec2<i32>(1, 0), layer, 0).r;
    let h01 = textureLoad(height_tiles, local + vec2<i32>(0, 1), layer, 0).r;
    let h11 = textureLoad(height_tiles, local + vec2<i32>(1, 1), layer, 0).r;
    // The remainder at this level: the dropped low bits plus the level-0 remainder, scaled by a
    // power of two (exact).
    let mask = (1u << level) - 1u;
    let scale = ldexp(1.0, -i32(level));
    let f = vec2<f32>(mul(f32(s0.x & mask) + p.frac.x, scale), mul(f32(s0.y & mask) + p.frac.y, scale));
    let drawn = drawn_ground(s, vec4<f32>(h00, h10, h01, h11), f);
    let per_m = mul(scale, u.inv_spacing_m);
    return Ground(drawn.height_m, vec2<f32>(mul(drawn.slope.x, per_m), mul(drawn.slope.y, per_m)), level, true);
}

// Palette index of level-1 land-cover texel `q` (`shared/landcover.wgsl`), and the level it came from.
fn class_at(q: vec2<u32>, wanted: u32) -> vec2<u32> {
    return landcover_class(q, wanted, u.lcc_levels, u.lcc_sub_bits);
}

// How far a seed's land-cover read moves, texels, each way in [-0.5, 0.5) (Rust: the twin's and
// the oracle's `class_offset`).
fn class_offset(address: vec2<i32>, rank: u32) -> vec2<f32> {
    let h = pcg(seed_hash(address, rank) ^ CLASS_EDGE_SALT);
    return vec2<f32>(unit(h) - 0.5, unit(pcg(h)) - 0.5);
}

// Pixel column holding clip-space x at distance w (x / w in NDC): a first guess by division,
// settled by exact comparisons against the pixel edges (`step` NDC units apart).
fn pixel_of(x: f32, w: f32, n: u32, step: f32) -> u32 {
    let guess = clamp((x / w * 0.5 + 0.5) * f32(n), 0.0, f32(n - 1u));
    var i = u32(guess);
    for (var k = 0; k < 4; k += 1) {
        if i > 0u && x < mul(mul(f32(i), step) - 1.0, w) {
            i -= 1u;
        } else if i + 1u < n && x >= mul(mul(f32(i + 1u), step) - 1.0, w) {
            i += 1u;
        }
    }
    return i;
}

// The seed's fate: a counter index (COUNT_SELECTED when kept), its record and draw group.
struct Outcome {
    count: u32,
    record: SeedRecord,
    key: u32,
}

fn select_seed(cell: SeedCell, rank: u32) -> Outcome {
    var out: Outcome;
    out.count = COUNT_CLASS;
    let pos_unit = patterns[cell.pattern * u.seeds_per_pattern + rank];
    // Outside the dataset there is no class. It ends at its last sample, where the terrain mesh
    // does: a seed between it and the land cover's edge would stand beyond the ground.
    let sample = grid_pos(cell.height_sample, cell.height_frac, pos_unit, u.cell_in_samples);
    let last = vec2<i32>(u.height_size) - 1;
    let beyond = any(sample.texel > last) || any((sample.texel == last) & (sample.frac > vec2<f32>(0.0)));
    if any(sample.texel < vec2<i32>(0)) || beyond || u.lcc_sub_bits == 0u {
        return out;
    }
    let lcc = grid_pos(cell.lcc_texel, cell.lcc_frac, pos_unit, u.cell_in_lcc_texels);
    // A class boundary, dithered: the class is read up to half a texel away from the seed, by a
    // hash of its own, so a seed near a boundary takes the neighbour's class with the share
    // bilinear interpolation gives it, and a forest's edge is as smooth as its seeds are dense,
    // not a staircase of the land cover's cells. Only between classes that grow: a seed whose own
    // cell grows nothing (water, no data, a class without rules) stays bare, so shores and the
    // data's edge stay where the land cover puts them.
    var step = vec2<i32>(0);
    if u.class_edge_dither != 0u {
        step = vec2<i32>(floor(lcc.frac + class_offset(cell.address, rank)));
    }
    let last_lcc = vec2<i32>(u.lcc_size) - 1;
    if any(step != vec2<i32>(0)) {
        let own = class_at(vec2<u32>(clamp(lcc.texel, vec2<i32>(0), last_lcc)), cell.lcc_level);
        if own.x >= arrayLength(&class_table) || !(class_table[own.x].rank_limit[0] > 0.0) {
            return out;
        }
    }
    let q = vec2<u32>(clamp(lcc.texel + step, vec2<i32>(0), last_lcc));
    let found = class_at(q, cell.lcc_level);
    if found.x >= arrayLength(&class_table) {
        return out;
    }
    let seeds = class_table[found.x];
    var k = 0u;
    while k < MAX_SPECIES_PER_CLASS && !(f32(rank) < seeds.rank_limit[k]) {
        k += 1u;
    }
    if k == MAX_SPECIES_PER_CLASS {
        return out;
    }
    let species_index = seeds.species[k];
    let species = species_table[species_index];

    out.count = COUNT_RULE;
    let ground = ground_at(sample);
    let slope_sq = mul(ground.gradient.x, ground.gradient.x) + mul(ground.gradient.y, ground.gradient.y);
    if !ground.found || ground.height_m < species.altitude_m.x || ground.height_m > species.altitude_m.y
        || slope_sq > species.max_slope_tan_sq {
        return out;
    }

    let hash = seed_hash(cell.address, rank);
    // The photograph's vegetation index: a rule of where plants grow, as altitude and slope are.
    if u.vegetation.x != 0.0
        && !vegetation_grows(grid_pos(cell.imagery_texel, cell.imagery_frac, pos_unit, u.cell_in_imagery_texels), hash) {
        return out;
    }
    let height_m = species.height_m.x + mul(species.height_m.y - species.height_m.x, unit(hash));
    // The seed's grid offset from its cell's corner and from the camera; its foot on the ground,
    // placed.
    let in_cell = vec2<f32>(mul(pos_unit.x, u.cell_m), mul(pos_unit.y, u.cell_m));
    let rel_xy = cell.rel_m + in_cell;
    let foot = placed_m(cell.earth, vec3<f32>(in_cell, ground.height_m));

    // Radial LOD: thresholds shrink with the seed's size below the reference height; a class
    // stops at its own last LOD.
    out.count = COUNT_DISTANCE;
    let distance_sq = mul(foot.x, foot.x) + mul(foot.y, foot.y) + mul(foot.z, foot.z);
    let size_scale = min(1.0, mul(height_m, u.inv_reference_height_m));
    let lods = min(seeds.lods, SEED_LODS);
    var lod = 0u;
    loop {
        if lod >= lods {
            return out;
        }
        let reach = mul(u.draw_reach_m[lod], size_scale);
        if distance_sq < mul(reach, reach) {
            break;
        }
        lod += 1u;
    }

    // Frustum: the bounding sphere, centred half-way up, against the NDC square grown by ε.
    // A plant stands along the local vertical, its anchor sunk along it.
    out.count = COUNT_FRUSTUM;
    let sink_m = mul(height_m, u.sink_fraction);
    let up = up_at(cell.earth, in_cell);
    let base = foot - mul3(up, sink_m);
    // The wind moves no point of a plant farther than this (`seeds::wind`): its bounds grow by it.
    let sway_m = mul(height_m, mul(species.wind_bend, u.wind_reach_per_height));
    let radius_m = mul(height_m, species.radius_per_height) + sway_m;
    let centre = to_clip(base + mul3(up, mul(height_m, 0.5)));
    if centre.w < -radius_m {
        return out;
    }
    let grown = mul(1.0 + u.frustum_epsilon, centre.w);
    if abs(centre.x) > grown + mul(radius_m, u.clip_row_len.x)
        || abs(centre.y) > grown + mul(radius_m, u.clip_row_len.y) {
        return out;
    }

    // Occlusion: the summit's distance against the terrain depth around it (the nearest edge
    // pixels when it is off screen), with the tolerance the coarse far mesh needs.
    out.count = COUNT_OCCLUSION;
    // Swaying, the summit may rise into view by as much (and come as much nearer).
    let summit = to_clip(base + mul3(up, height_m) + mul3(up, sway_m));
    if summit.w > u.near_m {
        let px = vec2<i32>(i32(pixel_of(summit.x, summit.w, u.screen_px.x, u.ndc_per_px.x)),
                           i32(pixel_of(-summit.y, summit.w, u.screen_px.y, u.ndc_per_px.y)));
        // The terrain around the summit's pixel decides, unless it disagrees with itself: then
        // the summit sits within a pixel of a silhouette, which the mesh and the pixel grid are
        // both too coarse to place, and a march over the DEM settles it.
        var farthest = 1.0;
        var nearest = 0.0;
        let last = vec2<i32>(u.screen_px) - 1;
        for (var dy = -OCCLUSION_FOOTPRINT_PX; dy <= OCCLUSION_FOOTPRINT_PX; dy += 1) {
            for (var dx = -OCCLUSION_FOOTPRINT_PX; dx <= OCCLUSION_FOOTPRINT_PX; dx += 1) {
                let d = textureLoad(depth, clamp(px + vec2<i32>(dx, dy), vec2<i32>(0), last), 0);
                farthest = min(farthest, d);
                nearest = max(nearest, d);
            }
        }
        let tolerance_m = u.occlusion_tolerance_m + mul(u.occlusion_tolerance_per_m, summit.w) + sway_m;
        let behind_m = summit.w - tolerance_m;
        var hidden = mul(behind_m, farthest) > u.near_m;
        if !hidden && mul(behind_m, nearest) > u.near_m {
            if u.refine_max_steps == 0u {
                hidden = mul(behind_m, textureLoad(depth, px, 0)) > u.near_m;
            } else {
                // The march walks the grid: the summit's offset and height, from the camera's.
                let summit_rel_z = ground.height_m - u.camera_z_m - sink_m + height_m + sway_m;
                hidden = dem_blocks(vec3<f32>(rel_xy, summit_rel_z));
            }
        }
        if hidden {
            return out;
        }
    }

    out.count = COUNT_SELECTED;
    let drawn = species_index + seed_variant(hash, species.variants);
    out.key = seed_group(drawn, lod);
    let imagery = grid_pos(cell.imagery_texel, cell.imagery_frac, pos_unit, u.cell_in_imagery_texels);
    out.record = SeedRecord(
        base,
        height_m,
        cell.address,
        rank,
        pack_species_lod(SpeciesLod(drawn, lod, u32(lod + 1u == lods), found.y, ground.level)),
        pcg(hash),
        ground_colour(imagery, hash),
        radius_m,
        ground.height_m,
    );
    return out;
}
