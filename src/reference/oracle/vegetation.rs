//! How it works: the exact oracle's reading of the imagery's vegetation index
//! (`dataset::vegetation`), pass 3's rule of where plants grow beside altitude and slope. The
//! level-0 imagery tiles under the view's region are decoded once (alpha only); a seed's index is
//! the bilinear mean of the coded alphas of the four texels around it (those with data; none:
//! the land cover alone decides), in f64, and the seed grows where a hash of its own lies below
//! the ramp `seeds.vegetation_*` at that index.

use std::collections::HashMap;

use glam::DVec2;

use crate::config::Settings;
use crate::dataset::{Dataset, PackError, TileId, imagery_texel_at};
use crate::gpu::layout::{IMAGERY_TILE_TEXELS, VEGETATION_CODE_STEPS, VEGETATION_SALT};
use crate::seeds::{pcg, unit};

/// The coded alphas of the level-0 imagery tiles under a region, with the ramp.
pub(super) struct Vegetation {
    /// (texel_m, half a height spacing, level-0 size), the ramp (bare, full); `None` where the
    /// imagery carries no index.
    grid: Option<(f64, f64, [u32; 2], [f64; 2])>,
    tiles: HashMap<[u32; 2], Vec<u8>>,
}

impl Vegetation {
    pub(super) fn load(
        dataset: &Dataset,
        settings: &Settings,
        min_m: [f64; 2],
        max_m: [f64; 2],
    ) -> Result<Self, PackError> {
        let (Some(layer), Some(meta), Some(_)) =
            (&dataset.imagery, &dataset.manifest.imagery, &dataset.manifest.vegetation)
        else {
            return Ok(Self { grid: None, tiles: HashMap::new() });
        };
        let ramp = [settings.seeds.vegetation_bare, settings.seeds.vegetation_full];
        let grid = (meta.texel_m, 0.5 * dataset.manifest.height.spacing_m, layer.pyramid.size, ramp);
        let mut out = Self { grid: Some(grid), tiles: HashMap::new() };
        // One texel of margin: the bilinear reads reach half a texel past a seed.
        let (lo, hi) = (out.texel(DVec2::from(min_m), -1.0), out.texel(DVec2::from(max_m), 1.0));
        for ty in lo[1] / IMAGERY_TILE_TEXELS..=hi[1] / IMAGERY_TILE_TEXELS {
            for tx in lo[0] / IMAGERY_TILE_TEXELS..=hi[0] / IMAGERY_TILE_TEXELS {
                let texels = layer.tile_texels(TileId::new(0, tx, ty))?;
                out.tiles.insert([tx, ty], texels.chunks_exact(4).map(|t| t[3]).collect());
            }
        }
        Ok(out)
    }

    /// The level-0 texel holding grid point `p` moved by `shift` texels, clamped to the layer.
    fn texel(&self, p: DVec2, shift: f64) -> [u32; 2] {
        let Some((texel_m, half_spacing_m, size, _)) = self.grid else { return [0; 2] };
        let q = [p.x, p.y].map(|v| ((v + half_spacing_m) / texel_m + shift).floor().max(0.0) as u64);
        [0, 1].map(|a| q[a].min(u64::from(size[a] - 1)) as u32)
    }

    fn alpha(&self, t: [u32; 2]) -> u8 {
        let (tile, index) = imagery_texel_at(t);
        self.tiles.get(&[tile.x, tile.y]).and_then(|alphas| alphas.get(index)).copied().unwrap_or(0)
    }

    /// Whether seed `hash` grows at grid point `p` by the vegetation index.
    pub(super) fn grows(&self, p: DVec2, hash: u32) -> bool {
        let Some((texel_m, half_spacing_m, size, [bare, full])) = self.grid else { return true };
        // Texel centres lie half a texel in.
        let c = [p.x, p.y].map(|v| (v + half_spacing_m) / texel_m - 0.5);
        let below = c.map(f64::floor);
        let (mut alpha, mut weight) = (0.0, 0.0);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let d = [dx, dy];
            let t: [u32; 2] =
                std::array::from_fn(|a| (below[a] as i64 + d[a]).clamp(0, i64::from(size[a]) - 1) as u32);
            let side = |a: usize| if d[a] == 1 { c[a] - below[a] } else { 1.0 - (c[a] - below[a]) };
            let a = self.alpha(t);
            if a > 0 {
                alpha += side(0) * side(1) * f64::from(a) / 255.0;
                weight += side(0) * side(1);
            }
        }
        if weight <= 0.0 {
            return true;
        }
        let index = ((alpha / weight) * 255.0 - 1.0) * 2.0 / f64::from(VEGETATION_CODE_STEPS) - 1.0;
        let growth = ((index - bare) / (full - bare)).clamp(0.0, 1.0);
        f64::from(unit(pcg(hash ^ VEGETATION_SALT))) < growth
    }
}
