//! The depth pyramid's CPU half: the size of each level, and the pyramid as CPU data (read back
//! from the GPU, or reduced by the twin), which the Tile Load Map's twin reads.

/// A depth pyramid on the CPU: level sizes and texels (top row first) of every level.
#[derive(Debug, Clone, PartialEq)]
pub struct HizMips {
    /// Width and height of each level in texels, level 0 (half the depth target) first.
    pub sizes: Vec<[u32; 2]>,
    /// Each level's texels, row-major: the minimum reversed-Z depth (farthest surface) they cover.
    pub levels: Vec<Vec<f32>>,
}

impl HizMips {
    /// Texel (`x`, `y`) of `level`.
    pub fn texel(&self, level: u32, x: u32, y: u32) -> f32 {
        let [w, _] = self.sizes[level as usize];
        self.levels[level as usize][(y * w + x) as usize]
    }
}

/// Sizes of the levels of the pyramid of a `width` × `height` depth target.
pub fn level_sizes(width: u32, height: u32) -> Vec<[u32; 2]> {
    let mut sizes = vec![[(width / 2).max(1), (height / 2).max(1)]];
    while let Some(&[w, h]) = sizes.last().filter(|s| s[0] > 1 || s[1] > 1) {
        sizes.push([(w / 2).max(1), (h / 2).max(1)]);
    }
    sizes
}
