//! How it works: everything a texcell samples, derived from the finest slices (Decaudin & Neyret
//! 2004, § 5 and 6). Slices are premultiplied RGBA in linear light, f32 while they are built, so
//! averaging and compositing never bleed colour from transparent texels.
//! - **The slice pyramid** `S_i`, i = N down to 0: `S_N` is the 2^N baked slices (bottom first);
//!   slice j of `S_i` is the 2^(N − i) finest slices it spans, each *over* the ones below it (the
//!   transparency equation C̄ = C̄_front + (1 − A_front) C̄_back, the upper slice in front: the
//!   forest is seen from above), not their average: the occlusion along the slicing direction is
//!   not linear. Composited texel by texel at full resolution, then halved per level (`S_i`'s
//!   side is L / 2^(N − i)) by 2 × 2 premultiplied box filters.
//! - **A mip chain per slice**, 2 × 2 premultiplied box filters: within a slice, filtering is
//!   linear. The sample wraps around (a torus), so no level has an edge.
//! - **The 3D texture** of silhouette texcells: `S_N` stacked, with its own mip chain of
//!   2 × 2 × 2 boxes (isotropic and linear, as the paper accepts for distant silhouettes).
//!
//! Images are finally stored as RGBA8 with the (premultiplied) colour sRGB-encoded, as the GPU's
//! sRGB formats decode it before filtering.

/// One premultiplied RGBA texel in linear light.
pub type Texel = [f32; 4];

/// A square image of premultiplied texels, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// Texels along each side.
    pub side: u32,
    /// `side`² texels.
    pub texels: Vec<Texel>,
}

impl Layer {
    /// A transparent layer.
    pub fn empty(side: u32) -> Self {
        Self { side, texels: vec![[0.0; 4]; (side * side) as usize] }
    }
}

/// `front` over `back`, premultiplied.
pub fn over(front: Texel, back: Texel) -> Texel {
    let k = 1.0 - front[3];
    [front[0] + k * back[0], front[1] + k * back[1], front[2] + k * back[2], front[3] + k * back[3]]
}

/// `layer` halved along each side by 2 × 2 boxes (a 1-texel layer stays as it is).
pub fn halve(layer: &Layer) -> Layer {
    if layer.side <= 1 {
        return layer.clone();
    }
    let side = layer.side / 2;
    let at = |x: u32, y: u32| layer.texels[(y * layer.side + x) as usize];
    let texels = (0..side)
        .flat_map(|y| (0..side).map(move |x| (x, y)))
        .map(|(x, y)| {
            let q = [at(2 * x, 2 * y), at(2 * x + 1, 2 * y), at(2 * x, 2 * y + 1), at(2 * x + 1, 2 * y + 1)];
            std::array::from_fn(|c| q.iter().map(|t| t[c]).sum::<f32>() * 0.25)
        })
        .collect();
    Layer { side, texels }
}

/// Every level of `finest`'s mip chain, `finest` first, down to 1 texel.
pub fn mip_chain(finest: Layer) -> Vec<Layer> {
    let mut chain = vec![finest];
    while chain[chain.len() - 1].side > 1 {
        let next = halve(&chain[chain.len() - 1]);
        chain.push(next);
    }
    chain
}

/// The slice pyramid from the finest slices (bottom first, 2^N of them, all of one side): level
/// 0 of the result is `finest` itself (`S_N`), level k has 2^(N − k) slices of side / 2^k. Each
/// coarser slice composites its 2^k finest slices at their full resolution, then halves: the
/// opacity rule applies texel by texel, before any averaging (compositing already averaged layers
/// would treat a gap in one layer as half covered by the other).
pub fn slice_pyramid(finest: Vec<Layer>) -> Vec<Vec<Layer>> {
    let n = finest.len();
    let mut levels = Vec::new();
    let mut group = 2;
    while group <= n {
        let level: Vec<Layer> = finest
            .chunks_exact(group)
            .map(|slices| {
                let side = slices[0].side;
                let mut texels = vec![[0.0f32; 4]; (side * side) as usize];
                // Bottom first: each slice goes over what lies below it.
                for slice in slices {
                    for (t, &s) in texels.iter_mut().zip(&slice.texels) {
                        *t = over(s, *t);
                    }
                }
                let mut layer = Layer { side, texels };
                for _ in 0..group.ilog2() {
                    layer = halve(&layer);
                }
                layer
            })
            .collect();
        levels.push(level);
        group *= 2;
    }
    levels.insert(0, finest);
    levels
}

/// A box of premultiplied texels, `side`² × `depth`, slice by slice (bottom first), each top row
/// first.
#[derive(Debug, Clone, PartialEq)]
pub struct Volume {
    /// Texels along x and y.
    pub side: u32,
    /// Slices along z.
    pub depth: u32,
    /// `side`² × `depth` texels.
    pub texels: Vec<Texel>,
}

/// The 3D mip chain of the slices stacked: level 0 holds them as they are, each next level
/// halves every dimension (none below 1) by averaging the boxes it covers.
pub fn volume_chain(slices: &[Layer]) -> Vec<Volume> {
    let side = slices.first().map_or(1, |l| l.side);
    let texels = slices.iter().flat_map(|l| l.texels.iter().copied()).collect();
    let mut chain = vec![Volume { side, depth: slices.len() as u32, texels }];
    while let Some(v) = chain.last().filter(|v| v.side > 1 || v.depth > 1) {
        let (side, depth) = ((v.side / 2).max(1), (v.depth / 2).max(1));
        let (sx, sz) = (v.side / side, v.depth / depth);
        let at = |x: u32, y: u32, z: u32| v.texels[((z * v.side + y) * v.side + x) as usize];
        let mut texels = Vec::with_capacity((side * side * depth) as usize);
        for z in 0..depth {
            for y in 0..side {
                for x in 0..side {
                    let mut sum = [0.0f32; 4];
                    for (dz, dy, dx) in
                        (0..sz).flat_map(|dz| (0..sx).flat_map(move |dy| (0..sx).map(move |dx| (dz, dy, dx))))
                    {
                        let t = at(sx * x + dx, sx * y + dy, sz * z + dz);
                        for c in 0..4 {
                            sum[c] += t[c];
                        }
                    }
                    let n = (sx * sx * sz) as f32;
                    texels.push(sum.map(|s| s / n));
                }
            }
        }
        chain.push(Volume { side, depth, texels });
    }
    chain
}

/// A linear-light value in [0, 1] as an 8-bit sRGB code.
pub fn encode_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round() as u8
}

/// An 8-bit sRGB code in linear light.
pub fn decode_srgb(code: u8) -> f32 {
    let c = f32::from(code) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// `texels` as RGBA8: colour sRGB-encoded, alpha linear.
pub fn encode(texels: &[Texel]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| {
            [
                encode_srgb(t[0]),
                encode_srgb(t[1]),
                encode_srgb(t[2]),
                (t[3].clamp(0.0, 1.0) * 255.0).round() as u8,
            ]
        })
        .collect()
}

/// RGBA8 (colour sRGB-encoded, alpha linear) as texels.
pub fn decode(bytes: &[u8]) -> Vec<Texel> {
    bytes
        .chunks_exact(4)
        .map(|t| [decode_srgb(t[0]), decode_srgb(t[1]), decode_srgb(t[2]), f32::from(t[3]) / 255.0])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(side: u32, t: Texel) -> Layer {
        Layer { side, texels: vec![t; (side * side) as usize] }
    }

    #[test]
    fn coarser_slices_composite_by_opacity_not_by_average() {
        // An opaque red slice over a transparent one stays opaque red; averaged, it would be
        // half transparent (the paper's fig. 4).
        let red = [0.8, 0.0, 0.0, 1.0];
        let pyramid = slice_pyramid(vec![flat(4, [0.0; 4]), flat(4, red)]);
        assert_eq!(pyramid.len(), 2);
        assert_eq!((pyramid[1].len(), pyramid[1][0].side), (1, 2));
        assert!(pyramid[1][0].texels.iter().all(|&t| t == red));
        // The upper slice is in front: a half-transparent green top over opaque blue.
        let green = [0.0, 0.25, 0.0, 0.5];
        let blue = [0.0, 0.0, 0.6, 1.0];
        let top = slice_pyramid(vec![flat(2, blue), flat(2, green)]);
        assert_eq!(top[1][0].texels[0], [0.0, 0.25, 0.3, 1.0]);
        // Eight slices: four levels, 8, 4, 2, 1 slices, sides 8, 4, 2, 1.
        let eight = slice_pyramid((0..8).map(|_| flat(8, [0.1, 0.1, 0.1, 0.2])).collect());
        let shape: Vec<(usize, u32)> = eight.iter().map(|l| (l.len(), l[0].side)).collect();
        assert_eq!(shape, [(8, 8), (4, 4), (2, 2), (1, 1)]);
        // Eight slices of opacity 0.2 make 1 − 0.8⁸ together.
        assert!((eight[3][0].texels[0][3] - (1.0 - 0.8f32.powi(8))).abs() < 1e-6);
    }

    #[test]
    fn mips_and_the_volume_keep_the_mean() {
        let mut layer = Layer::empty(8);
        for (i, t) in layer.texels.iter_mut().enumerate() {
            let a = (i % 7) as f32 / 7.0;
            *t = [0.5 * a, 0.2 * a, 0.1 * a, a];
        }
        let mean = |ts: &[Texel]| ts.iter().map(|t| t[3]).sum::<f32>() / ts.len() as f32;
        let chain = mip_chain(layer.clone());
        assert_eq!(chain.iter().map(|l| l.side).collect::<Vec<_>>(), [8, 4, 2, 1]);
        for l in &chain {
            assert!((mean(&l.texels) - mean(&layer.texels)).abs() < 1e-5);
        }
        let volume = volume_chain(&[layer.clone(), Layer::empty(8), layer.clone(), layer]);
        let dims: Vec<(u32, u32)> = volume.iter().map(|v| (v.side, v.depth)).collect();
        assert_eq!(dims, [(8, 4), (4, 2), (2, 1), (1, 1)]);
        let whole = mean(&volume[0].texels);
        assert!(volume.iter().all(|v| (mean(&v.texels) - whole).abs() < 1e-5));
    }

    #[test]
    fn storage_round_trips_within_a_code() {
        let texels: Vec<Texel> = (0..=255)
            .map(|i| {
                let c = decode_srgb(i);
                [c, c * 0.5, 0.0, f32::from(i) / 255.0]
            })
            .collect();
        let bytes = encode(&texels);
        assert_eq!(bytes.chunks_exact(4).map(|t| t[0]).collect::<Vec<_>>(), (0..=255).collect::<Vec<u8>>());
        let back = decode(&bytes);
        assert!(back.iter().zip(&texels).all(|(a, b)| (0..4).all(|c| (a[c] - b[c]).abs() < 0.01)));
    }
}
