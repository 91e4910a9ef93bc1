// Pass 3's occlusion march (part of the seed_select shader, after seed_select.wgsl, whose bindings
// and ground reads it uses): whether the drawn ground (finest resident heights) rises above the
// segment from the eye to a seed's summit at any of its samples, taken at least every half height
// spacing (a power of two of them, at most `refine_max_steps`), positions by products only, so the
// twin (`reference/seed_select/ground.rs`) agrees exactly.
//
// It leaps over runs of samples where the segment passes at or above every height that can be
// drawn under them, taking the decision visiting them would:
//   - a tile of `leap_level` (`height_tile_max_m`: the top of every level-0 sample under it and
//     its neighbours). Whatever level draws a sample there, its cell's corners lie in those tiles
//     (that level's cells are no wider than the tile), and decimated heights never leave their
//     level-0 range.
//   - a block of HEIGHT_BLOCK_CELLS cells of the resident tile that draws the sample
//     (`height_block_max_m`: the highest of the block's corner samples, per slot, made when the
//     tile was placed), when that tile is at most HEIGHT_BLOCK_LEVELS levels coarse: the block then
//     lies in a single tile of every finer level, each of which the search for the finest resident
//     tile found absent, so the tile draws every sample in the block.
// A leap goes to the last sample still in the tile or block and still at or above its top, found
// by bisection: positions are monotone in the sample number (rounding is monotone), so those
// samples are a run from the first.

// Sample `k` of the march towards `summit_rel` (grid offset from the camera and height above it;
// `dt` apart in its parameter): where it lies in the height grid, the segment's height there
// above the datum, and a floor under that height linear in k. On the Earth the straight segment
// sags below the line between its ends' heights by t (1 − t) times `sag_m`, (L² + 2 Δz²) / 2R:
// the Earth's fall under it, and the verticals' convergence, which puts its higher points over
// nearer grid points (L its length over the grid, Δz its rise, t the grid's fraction); the floor
// drops the whole t `sag_m`. A leap is judged against the floor: linear, so where it holds at
// two samples it holds between them (the sagging height is convex, and could dip between), and
// under the height, so a leap never skips a sample whose ground the segment passes below.
struct MarchPoint {
    sample: GridPos,
    z_m: f32,
    floor_m: f32,
}

fn march_point(summit_rel: vec3<f32>, sag_m: f32, k: u32, dt: f32) -> MarchPoint {
    let t = mul(f32(k), dt);
    let p = vec3<f32>(mul(summit_rel.x, t), mul(summit_rel.y, t), mul(summit_rel.z, t));
    let line_m = p.z + u.camera_z_m;
    let sag_t = mul(sag_m, t);
    return MarchPoint(
        grid_pos(u.camera_sample, u.camera_sample_frac, p.xy, u.inv_spacing_m),
        line_m - (sag_t - mul(sag_t, t)),
        line_m - sag_t,
    );
}

fn in_dataset(sample: GridPos) -> bool {
    return all(sample.texel >= vec2<i32>(0)) && all(sample.texel < vec2<i32>(u.height_size));
}

// The finest level whose tiles are wider than a cell of the coarsest level.
fn leap_level() -> u32 {
    return u.height_level_count - min(u.height_level_count, countTrailingZeros(HEIGHT_TILE_CELLS) + 1u);
}

// A run of samples the march may leap over: those in the level-`level` grid square `square` of
// `cells` cells (a tile or a block), while the segment stays at or above `top_m`.
struct Leap {
    level: u32,
    cells: u32,
    square: vec2<u32>,
    top_m: f32,
}

fn leap_holds(leap: Leap, m: MarchPoint) -> bool {
    let square = (vec2<u32>(m.sample.texel) >> vec2<u32>(leap.level)) / leap.cells;
    return in_dataset(m.sample) && all(square == leap.square) && leap.top_m <= m.floor_m;
}

// The last sample from `k` (where `leap` holds) to `steps` where it still holds.
fn leap_end(summit_rel: vec3<f32>, sag_m: f32, k: u32, steps: u32, dt: f32, leap: Leap) -> u32 {
    var clear = k;
    var beyond = steps;
    while beyond - clear > 1u {
        let mid = clear + (beyond - clear) / 2u;
        if leap_holds(leap, march_point(summit_rel, sag_m, mid, dt)) {
            clear = mid;
        } else {
            beyond = mid;
        }
    }
    return clear;
}

fn dem_blocks(summit_rel: vec3<f32>) -> bool {
    let length_sq = mul(summit_rel.x, summit_rel.x) + mul(summit_rel.y, summit_rel.y);
    let sag_m = mul(u.chord_sag_per_m2, length_sq + mul(2.0, mul(summit_rel.z, summit_rel.z)));
    let wanted_sq = mul(mul(length_sq, 4.0), mul(u.inv_spacing_m, u.inv_spacing_m));
    var steps = 2u;
    while steps < u.refine_max_steps && f32(steps * steps) < wanted_sq {
        steps *= 2u;
    }
    let dt = ldexp(1.0, -i32(countTrailingZeros(steps)));
    let tile_level = leap_level();
    var k = 1u;
    while k < steps {
        let m = march_point(summit_rel, sag_m, k, dt);
        if !in_dataset(m.sample) {
            k += 1u;
            continue;
        }
        let s0 = vec2<u32>(m.sample.texel);
        let tile_top_m = height_tile_max_m[height_tile_at(s0, tile_level).z];
        if tile_top_m <= m.floor_m {
            let square = (s0 >> vec2<u32>(tile_level)) / HEIGHT_TILE_CELLS;
            let leap = Leap(tile_level, HEIGHT_TILE_CELLS, square, tile_top_m);
            k = leap_end(summit_rel, sag_m, k, steps, dt, leap) + 1u;
            continue;
        }
        let hit = height_tile(s0);
        if hit.slot != PAGE_EMPTY && hit.level <= HEIGHT_BLOCK_LEVELS {
            let block = (s0 >> vec2<u32>(hit.level)) / HEIGHT_BLOCK_CELLS;
            let local = block - hit.tile * HEIGHT_TILE_BLOCKS;
            // A sample past the tile's last cell (its far edge) has no block of its own.
            if all(local < vec2<u32>(HEIGHT_TILE_BLOCKS)) {
                let slot_blocks = u32(page_layer(hit.slot)) * HEIGHT_TILE_BLOCKS * HEIGHT_TILE_BLOCKS;
                let block_top_m = height_block_max_m[slot_blocks + local.y * HEIGHT_TILE_BLOCKS + local.x];
                if block_top_m <= m.floor_m {
                    let leap = Leap(hit.level, HEIGHT_BLOCK_CELLS, block, block_top_m);
                    k = leap_end(summit_rel, sag_m, k, steps, dt, leap) + 1u;
                    continue;
                }
            }
        }
        let ground = ground_in(hit, m.sample);
        if ground.found && ground.height_m > m.z_m {
            return true;
        }
        k += 1u;
    }
    return false;
}
