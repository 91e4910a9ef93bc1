//! How it works: the CPU twin of `shaders/depth_pyramid.wgsl`: the same min-reduction, level by
//! level, each texel the minimum (farthest, in reversed-Z) of the texels it covers below, the last
//! texel of an odd edge covering three. The GPU pyramid must equal it exactly.

use crate::passes::depth_pyramid::frame::{HizMips, level_sizes};

/// The reference reduction of a `width` × `height` reversed-Z depth image (top row first):
/// each texel the minimum of what it covers, the last texel of an odd edge covering three.
pub fn depth_pyramid(depth: &[f32], width: u32, height: u32) -> HizMips {
    let sizes = level_sizes(width, height);
    let mut levels: Vec<Vec<f32>> = Vec::with_capacity(sizes.len());
    let mut source = ([width, height], depth.to_vec());
    for &size in &sizes {
        let covered = |x: u32, n: u32, source_n: u32| {
            let last = if x + 1 == n { source_n - 1 } else { 2 * x + 1 };
            (2 * x).min(source_n - 1)..=last.min(source_n - 1)
        };
        let mut texels = Vec::with_capacity((size[0] * size[1]) as usize);
        for y in 0..size[1] {
            for x in 0..size[0] {
                let mut farthest = f32::INFINITY;
                for sy in covered(y, size[1], source.0[1]) {
                    for sx in covered(x, size[0], source.0[0]) {
                        farthest = farthest.min(source.1[(sy * source.0[0] + sx) as usize]);
                    }
                }
                texels.push(farthest);
            }
        }
        levels.push(texels.clone());
        source = (size, texels);
    }
    HizMips { sizes, levels }
}
