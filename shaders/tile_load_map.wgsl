// Tile Load Map (pass 1, Amara et al. 2007 § 4.2): one invocation per cell of the camera-centred
// rings writes whether the cell is visible (and its seed pattern), the imagery and terrain levels
// it needs and its radial LOD. Its twin is src/reference/tile_load_map.rs: same steps, same f32
// operations in the same order, so the two agree bit for bit.
//
// Exactness rules: every decision compares products and sums, never sqrt, log2 or a quotient
// (a division only seeds a search that exact comparisons then settle). Every product goes through
// `mul`, which ORs a uniform zero into its bits: no compiler can fuse it with the following add
// into an FMA (fusing rounds once instead of twice, which the CPU would not reproduce).
// Everything large is subtracted on the CPU in f64: the cell extents arrive camera-relative.
// On the Earth a cell's grid box is bent onto it (`bent_box`) and culled by the horizon too.

struct TlmRing {
    origin_cell: vec2<i32>,
    height_level: u32,
    _pad: u32,
}

struct TlmUniforms {
    clip_from_view_world: mat4x4<f32>,
    frustum_planes: array<vec4<f32>, 5>,
    camera_z_m: f32,
    near_m: f32,
    occlusion_tolerance_m: f32,
    imagery_scale_sq: f32,
    radial_band_sq_m2: vec4<f32>,
    screen_px: vec2<u32>,
    ndc_per_px: vec2<f32>,
    hiz_mips: u32,
    imagery_levels: u32,
    height_lod_count: u32,
    rings: u32,
    cells: u32,
    corner_colours: u32,
    seed: u32,
    no_fuse: u32,
    occlusion_tolerance_per_m: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
    earth_bend: array<vec4<f32>, 2>,
    horizon: array<vec4<f32>, 4>,
    height_lod_range_m: array<vec4<f32>, MAX_LEVELS / 4u>,
    height_levels: array<vec4<u32>, MAX_LEVELS>,
    rings_info: array<TlmRing, TLM_MAX_RINGS>,
}

struct TlmSpan {
    rel_m: vec2<f32>,
    height_tiles: u32,
    flags: u32,
}

struct TlmCell {
    visibility: u32,
    imagery_lod: u32,
    height_lod: u32,
    radial_lod: u32,
}

// A storage binding, not a uniform one: Mesa lavapipe specialises a shader on the values of
// uniforms that steer loops and branches and keeps every variant, and these change every frame
// (a leak of about 0.5 MiB a frame, caught by data-tools/tests/globe_flight.rs).
@group(0) @binding(0) var<storage, read> u: TlmUniforms;
@group(0) @binding(1) var<storage, read> spans: array<TlmSpan>;
@group(0) @binding(2) var<storage, read> height_ranges_m: array<vec2<f32>>;
@group(0) @binding(3) var hiz: texture_2d<f32>;
@group(0) @binding(4) var<storage, read_write> cells_out: array<TlmCell>;

// a · b, correctly rounded and never fused into a following add (see the header).
fn mul(a: f32, b: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(a * b) | u.no_fuse);
}

fn length_sq(v: vec3<f32>) -> f32 {
    return mul(v.x, v.x) + mul(v.y, v.y) + mul(v.z, v.z);
}

// Union of the height ranges of the tiles a cell overlaps (at most 2 × 2).
fn height_range(ring: u32, tiles_x: u32, tiles_y: u32) -> vec2<f32> {
    let level = u.height_levels[u.rings_info[ring].height_level];
    var range = vec2<f32>(3.4e38, -3.4e38);
    let xs = unpack_tile_span(tiles_x);
    let ys = unpack_tile_span(tiles_y);
    for (var ty = ys.first; ty <= ys.last; ty += 1u) {
        for (var tx = xs.first; tx <= xs.last; tx += 1u) {
            let r = height_ranges_m[level.x + ty * level.y + tx];
            range = vec2<f32>(min(range.x, r.x), max(range.y, r.y));
        }
    }
    return range;
}

// A camera-relative box.
struct CellBox {
    lo: vec3<f32>,
    hi: vec3<f32>,
}

// The grid box `lo`..`hi` bent onto the Earth (`earth::horizon::EarthBend`): each corner falls by
// d² / 2R at its horizontal distance d (the low face by its farthest, the high by its nearest),
// and every face moves out by the mapping's other terms' bound, across and up and down. Flat,
// the box as it came.
fn bent_box(lo: vec3<f32>, hi: vec3<f32>) -> CellBox {
    let e = u.earth_bend[0];
    let ez = u.earth_bend[1];
    let far = max(abs(lo.xy), abs(hi.xy));
    let near = clamp(vec2<f32>(0.0), lo.xy, hi.xy);
    let far_sq = mul(far.x, far.x) + mul(far.y, far.y);
    let near_sq = mul(near.x, near.x) + mul(near.y, near.y);
    let l1 = far.x + far.y;
    let across = mul(e.y, l1) + mul(e.z, far_sq) + mul(e.w, mul(l1, far_sq));
    let margin = vec3<f32>(across, across, mul(ez.x, l1) + mul(ez.y, far_sq) + mul(ez.z, mul(far_sq, far_sq)));
    return CellBox(lo - margin - vec3<f32>(0.0, 0.0, mul(e.x, far_sq)), hi + margin - vec3<f32>(0.0, 0.0, mul(e.x, near_sq)));
}

// Whether the Earth hides camera-relative point `p` (`earth::horizon::HorizonCone::hides`).
fn below_horizon(p: vec3<f32>) -> bool {
    let h = u.horizon;
    let along = mul(h[3].x, p.x) + mul(h[3].y, p.y) + mul(h[3].z, p.z);
    if !(along > h[3].w) {
        return false;
    }
    let q = vec3<f32>(
        mul(h[0].x, p.x) + mul(h[0].y, p.y) + mul(h[0].z, p.z),
        mul(h[1].x, p.x) + mul(h[1].y, p.y) + mul(h[1].z, p.z),
        mul(h[2].x, p.x) + mul(h[2].y, p.y) + mul(h[2].z, p.z),
    );
    return mul(along, along) >= mul(length_sq(q), h[3].w);
}

// Whether the Earth hides the whole box: every corner.
fn beyond_horizon(b: CellBox) -> bool {
    for (var corner = 0u; corner < 8u; corner += 1u) {
        if !below_horizon(select(b.lo, b.hi, vec3<bool>((corner & 1u) != 0u, (corner & 2u) != 0u, (corner & 4u) != 0u))) {
            return false;
        }
    }
    return true;
}

// False when the box lies entirely behind one of the frustum's planes.
fn in_frustum(lo: vec3<f32>, hi: vec3<f32>) -> bool {
    for (var i = 0u; i < 5u; i += 1u) {
        let p = u.frustum_planes[i];
        let c = select(lo, hi, p.xyz >= vec3<f32>(0.0));
        if mul(p.x, c.x) + mul(p.y, c.y) + mul(p.z, c.z) + p.w < 0.0 {
            return false;
        }
    }
    return true;
}

// Clip-space x, y and w of camera-relative point `p` (z is the constant near_m).
fn project(p: vec3<f32>) -> vec3<f32> {
    let m = u.clip_from_view_world;
    let x = mul(m[0].x, p.x) + mul(m[1].x, p.y) + mul(m[2].x, p.z) + m[3].x;
    let y = mul(m[0].y, p.x) + mul(m[1].y, p.y) + mul(m[2].y, p.z) + m[3].y;
    let w = mul(m[0].w, p.x) + mul(m[1].w, p.y) + mul(m[2].w, p.z) + m[3].w;
    return vec3<f32>(x, y, w);
}

// The pixel (along one axis, 0 at the left / top) whose edge is the last at or before
// q / w in NDC: the largest i with q ≥ (i · ndc_per_px − 1) · w, clamped to the screen. The
// division only guesses i; the exact test walks it to the answer (at most 4 steps either way).
fn pixel_of(q: f32, w: f32, ndc_per_px: f32, pixels: u32) -> u32 {
    let n = i32(pixels);
    let guess = (q / w + 1.0) / ndc_per_px;
    var i = i32(clamp(floor(guess), -1.0, f32(n)));
    for (var k = 0; k < 4; k += 1) {
        if i < n && q >= mul(mul(f32(i + 1), ndc_per_px) - 1.0, w) {
            i += 1;
        }
    }
    for (var k = 0; k < 4; k += 1) {
        if i > -1 && q < mul(mul(f32(i), ndc_per_px) - 1.0, w) {
            i -= 1;
        }
    }
    return u32(clamp(i, 0, n - 1));
}

// True when the whole box lies more than the tolerance behind the farthest terrain over its
// screen rectangle, as the depth pyramid records it.
fn occluded(lo: vec3<f32>, hi: vec3<f32>) -> bool {
    var nearest_w = 3.4e38;
    var rect = vec4<u32>(0xffffffffu, 0xffffffffu, 0u, 0u);
    for (var corner = 0u; corner < 8u; corner += 1u) {
        let p = select(lo, hi, vec3<bool>((corner & 1u) != 0u, (corner & 2u) != 0u, (corner & 4u) != 0u));
        let clip = project(p);
        if clip.z < u.near_m {
            return false;
        }
        nearest_w = min(nearest_w, clip.z);
        let x = pixel_of(clip.x, clip.z, u.ndc_per_px.x, u.screen_px.x);
        let y = pixel_of(-clip.y, clip.z, u.ndc_per_px.y, u.screen_px.y);
        rect = vec4<u32>(min(rect.xy, vec2<u32>(x, y)), max(rect.zw, vec2<u32>(x, y)));
    }
    // The finest level at which the rectangle spans at most 2 × 2 texels.
    var level = 0u;
    var first = vec2<u32>(0u);
    var last = vec2<u32>(0u);
    loop {
        let size = textureDimensions(hiz, level);
        first = min(rect.xy >> vec2<u32>(level + 1u), size - 1u);
        last = min(rect.zw >> vec2<u32>(level + 1u), size - 1u);
        if all(last - first <= vec2<u32>(1u)) || level + 1u >= u.hiz_mips {
            break;
        }
        level += 1u;
    }
    var farthest_depth = 1.0;
    for (var y = first.y; y <= last.y; y += 1u) {
        for (var x = first.x; x <= last.x; x += 1u) {
            farthest_depth = min(farthest_depth, textureLoad(hiz, vec2<u32>(x, y), i32(level)).r);
        }
    }
    // Reversed-Z: view distance = near / depth. Culled when nearest_w − tolerance > near / depth,
    // i.e. (nearest_w − tolerance) · depth > near; the sky (depth 0) never occludes. The tolerance
    // grows with distance as the seeds' does (`config::OcclusionTolerance`).
    let tolerance_m = u.occlusion_tolerance_m + mul(u.occlusion_tolerance_per_m, nearest_w);
    return mul(nearest_w - tolerance_m, farthest_depth) > u.near_m;
}

// floor(log2(footprint / texel0) + bias) at squared distance `d_sq`, clamped to the levels:
// floor(log2(x²) / 2), with floor(log2) read from the exponent bits.
fn imagery_level(d_sq: f32) -> u32 {
    let x = mul(d_sq, u.imagery_scale_sq);
    let exponent = i32((bitcast<u32>(x) >> 23u) & 0xffu) - 127;
    return u32(clamp(exponent >> 1u, 0, i32(u.imagery_levels) - 1));
}

// The terrain's LOD at squared distance `d_sq`: the first whose range reaches it.
fn height_lod(d_sq: f32) -> u32 {
    for (var m = 0u; m < u.height_lod_count; m += 1u) {
        let range = u.height_lod_range_m[m / 4u][m % 4u];
        if d_sq <= mul(range, range) {
            return m;
        }
    }
    return u.height_lod_count - 1u;
}

fn tlm_cell(ring: u32, cx: u32, cy: u32) -> TlmCell {
    let culled = TlmCell(TLM_CULLED, 0u, 0u, RADIAL_INACTIVE);
    let sx = spans[(ring * 2u) * u.cells + cx];
    let sy = spans[(ring * 2u + 1u) * u.cells + cy];
    let flags = sx.flags & sy.flags;
    if (flags & TLM_SPAN_INSIDE) == 0u || (flags & TLM_SPAN_COVERED) != 0u {
        return culled;
    }
    let heights = height_range(ring, sx.height_tiles, sy.height_tiles);
    let lo = vec3<f32>(sx.rel_m.x, sy.rel_m.x, heights.x - u.camera_z_m);
    let hi = vec3<f32>(sx.rel_m.y, sy.rel_m.y, heights.y - u.camera_z_m);
    // Culled where it is drawn, on the Earth; its levels by the grid's distances, as the
    // terrain's LOD takes them.
    let placed = bent_box(lo, hi);
    if !in_frustum(placed.lo, placed.hi) || beyond_horizon(placed) || occluded(placed.lo, placed.hi) {
        return culled;
    }
    let near_sq = length_sq(clamp(vec3<f32>(0.0), lo, hi));
    let far_sq = length_sq(max(abs(lo), abs(hi)));

    var cell: TlmCell;
    cell.visibility = TLM_FIRST_PATTERN;
    if ring == 0u {
        let g = u.rings_info[0].origin_cell + vec2<i32>(i32(cx), i32(cy));
        cell.visibility = tlm_visibility(cell_pattern(bitcast<vec2<u32>>(g), u.seed, u.corner_colours));
    }
    cell.imagery_lod = 0u;
    if u.imagery_levels > 0u {
        cell.imagery_lod = pack_level_range(LevelRange(imagery_level(near_sq), imagery_level(far_sq)));
    }
    cell.height_lod = pack_level_range(LevelRange(height_lod(near_sq), height_lod(far_sq)));
    cell.radial_lod = RADIAL_INACTIVE;
    for (var k = i32(TLM_RADIAL_BANDS) - 1; k >= 0; k -= 1) {
        if near_sq < u.radial_band_sq_m2[k] {
            cell.radial_lod = u32(k);
        }
    }
    return cell;
}

@compute @workgroup_size(TLM_WORKGROUP, TLM_WORKGROUP, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= u.cells || id.y >= u.cells || id.z >= u.rings {
        return;
    }
    cells_out[(id.z * u.cells + id.y) * u.cells + id.x] = tlm_cell(id.z, id.x, id.y);
}
