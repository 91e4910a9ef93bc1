//! How it works: the CPU twin of `shaders/texcells.wgsl`'s choices at a point of the ground,
//! shader-shaped (the same f32 steps): where it reads the forest sample (`forest_uv`: the point's
//! cell and half, the half's edge colours from the lattice hash, the sample's triangle of that
//! half and colours, `texcell::tiling`), and how much of which forest stands there (`forest_at`:
//! the four nearest level-1 land-cover texels' dense flags, weighted bilinearly; the heaviest's
//! sample). The placement of patches is already CPU work (`passes::texcells::frame`). Tests hold
//! the shader's `forest_uv` equal to this one, bit for bit (`passes::texcells::gpu::probe`).

use crate::texcell::tiling::{Half, REFERENCE_CELLS, ground_sample_cell};

/// Where grid position `grid_m` reads the forest sample, in sample units (wrapping at 1), for
/// samples of ground cell `1 / inv_cell_m` in a world of germ `seed`.
pub fn forest_uv(grid_m: [f32; 2], inv_cell_m: f32, seed: u32) -> [f32; 2] {
    let p = grid_m.map(|g| g * inv_cell_m);
    let cell = p.map(f32::floor);
    let f = [p[0] - cell[0], p[1] - cell[1]];
    let half = if f[0] > f[1] { Half::Lower } else { Half::Upper };
    let sample = ground_sample_cell([cell[0] as i32, cell[1] as i32], half, seed);
    let scale = 1.0 / REFERENCE_CELLS as f32;
    [(sample[0] as f32 + f[0]) * scale, (sample[1] as f32 + f[1]) * scale]
}

/// How forest stands at a point: which sample, and how much (0 to 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forest {
    /// The forest sample's index.
    pub sample: u32,
    /// The bilinear weight of the dense texels around the point.
    pub coverage: f32,
}

/// The forest at grid position `grid_m`, with level-1 land-cover texel (0, 0)'s south-west corner
/// at `lcc_origin_m`, texels `1 / inv_texel_m` wide, `lcc_size` of them; `class_of` reads a
/// texel's palette index (`None`: not resident), `sample_of_class` maps it to a sample index + 1.
pub fn forest_at(
    grid_m: [f32; 2],
    lcc_origin_m: [f32; 2],
    inv_texel_m: f32,
    lcc_size: [u32; 2],
    class_of: impl Fn([u32; 2]) -> Option<u32>,
    sample_of_class: &[u32],
) -> Forest {
    let t = [0, 1].map(|a| (grid_m[a] - lcc_origin_m[a]) * inv_texel_m - 0.5);
    let base = t.map(f32::floor);
    let f = [t[0] - base[0], t[1] - base[1]];
    let (mut best, mut best_weight, mut coverage) = (0, 0.0f32, 0.0f32);
    for k in 0..4u32 {
        let offset = [(k & 1) as f32, (k >> 1) as f32];
        let q = [0, 1].map(|a| (base[a] + offset[a]).clamp(0.0, lcc_size[a] as f32 - 1.0) as u32);
        let Some(&sample) = class_of(q).and_then(|c| sample_of_class.get(c as usize)) else { continue };
        if sample == 0 {
            continue;
        }
        let mix = |a: f32, b: f32, t: f32| a * (1.0 - t) + b * t;
        let w = mix(1.0 - f[0], f[0], offset[0]) * mix(1.0 - f[1], f[1], offset[1]);
        coverage += w;
        if w > best_weight {
            best_weight = w;
            best = sample - 1;
        }
    }
    Forest { sample: best, coverage }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_texel_centre_is_all_its_own_class_and_edges_blend() {
        // A 4 × 4 map, dense (palette index 2 → sample 0) on its west half.
        let class_of = |q: [u32; 2]| Some(if q[0] < 2 { 2 } else { 1 });
        let table = [0, 0, 1];
        let at = |x: f32| forest_at([x, 45.0], [0.0, 0.0], 1.0 / 30.0, [4, 4], class_of, &table);
        assert_eq!(at(15.0).coverage, 1.0);
        assert_eq!(at(105.0).coverage, 0.0);
        // Half way between the last dense centre (45 m) and the first open one (75 m).
        assert!((at(60.0).coverage - 0.5).abs() < 1e-6);
        assert_eq!(at(60.0).sample, 0);
    }

    #[test]
    fn the_sample_wraps_and_every_ground_point_reads_inside_it() {
        for i in -50..50 {
            let grid = [i as f32 * 7.3, i as f32 * -3.1 + 0.4];
            let uv = forest_uv(grid, 1.0 / 32.0, 1);
            assert!(uv.iter().all(|&v| (0.0..1.0).contains(&v)), "{grid:?} → {uv:?}");
        }
    }
}
