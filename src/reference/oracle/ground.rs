//! How it works: what the oracle reads from the dataset, read once per view. `DemWindow` copies
//! the level-0 height samples of a rectangle out of their tiles into one dense array and answers
//! the drawn ground (`dataset::surface`), its gradient and the exact least clearance of a segment
//! over it (the DDA walk described in `reference::oracle`). `LandcoverTiles` decodes the level-1 land-cover tiles
//! under the same rectangle and answers palette indices.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use glam::{DVec2, DVec3};

use crate::dataset::lcc::{LCC_SOURCE_LEVEL, LccCoding};
use crate::dataset::surface::{diagonal_rises, drawn_height};
use crate::dataset::{Dataset, PackError, TileId};

/// Level-0 height samples [first, first + held) per axis, copied out of their tiles.
pub(super) struct DemWindow {
    spacing_m: f64,
    /// Samples per axis in the dataset.
    size: [u32; 2],
    first: [u32; 2],
    held: [u32; 2],
    heights_m: Vec<f32>,
}

impl DemWindow {
    /// The samples every cell touching the rectangle [min_m, max_m] needs.
    pub(super) fn load(dataset: &Dataset, min_m: [f64; 2], max_m: [f64; 2]) -> Result<Self, PackError> {
        let pyramid = &dataset.height.pyramid;
        let spacing_m = dataset.manifest.height.spacing_m;
        let size = pyramid.size.map(|n| n.max(1));
        let clamp = |v: f64, a: usize| (v.max(0.0) as u64).min(u64::from(size[a] - 1)) as u32;
        let first = [0, 1].map(|a| clamp((min_m[a] / spacing_m).floor() - 1.0, a));
        let last = [0, 1].map(|a| clamp((max_m[a] / spacing_m).ceil() + 1.0, a).max(first[a]));
        let held = [0, 1].map(|a| last[a] - first[a] + 1);
        let (tiles_at, extent) = (pyramid.tiles_at(0), pyramid.tile_extent());
        let mut tiles: HashMap<[u32; 2], Vec<f32>> = HashMap::new();
        let mut heights_m = Vec::with_capacity(held[0] as usize * held[1] as usize);
        for y in first[1]..=last[1] {
            for x in first[0]..=last[0] {
                let t = [(x / pyramid.tile).min(tiles_at[0] - 1), (y / pyramid.tile).min(tiles_at[1] - 1)];
                let samples = match tiles.entry(t) {
                    Entry::Occupied(e) => e.into_mut(),
                    Entry::Vacant(e) => e.insert(dataset.height_tile(TileId::new(0, t[0], t[1]))?),
                };
                let local =
                    [x - t[0] * pyramid.tile + pyramid.border, y - t[1] * pyramid.tile + pyramid.border];
                heights_m.push(samples[(local[1] * extent + local[0]) as usize]);
            }
        }
        Ok(Self { spacing_m, size, first, held, heights_m })
    }

    /// Sample (`i`, `j`) (dataset indices, clamped to the window).
    fn sample(&self, i: u32, j: u32) -> f64 {
        let x = i.saturating_sub(self.first[0]).min(self.held[0] - 1);
        let y = j.saturating_sub(self.first[1]).min(self.held[1] - 1);
        f64::from(self.heights_m[(y * self.held[0] + x) as usize])
    }

    /// The cell holding coordinate `v_m` along `axis` (its floor, clamped to the
    /// window's cells) and the coordinate in it, in cells.
    fn cell(&self, v_m: f64, axis: usize) -> (u32, f64) {
        let g = v_m / self.spacing_m;
        let lo = self.first[axis];
        let hi = (lo + self.held[axis]).saturating_sub(2).max(lo);
        debug_assert!(g >= f64::from(lo) - 1e-6 && g <= f64::from(hi) + 1.0 + 1e-6 || self.held[axis] < 2);
        let i = (g.floor().max(f64::from(lo)) as u32).min(hi);
        (i, g - f64::from(i))
    }

    /// The heights of cell (`i`, `j`)'s corners: south-west, south-east, north-west, north-east.
    fn corners(&self, i: u32, j: u32) -> [f64; 4] {
        [self.sample(i, j), self.sample(i + 1, j), self.sample(i, j + 1), self.sample(i + 1, j + 1)]
    }

    /// The drawn ground at `p` and its gradient (height per metre east, north).
    pub(super) fn ground(&self, p: DVec2) -> (f64, DVec2) {
        let ((i, u), (j, v)) = (self.cell(p.x, 0), self.cell(p.y, 1));
        let (height_m, slope) = drawn_height([i, j], self.corners(i, j), [u, v]);
        (height_m, DVec2::from(slope) / self.spacing_m)
    }

    /// The least of z(t) − sag_m t (1 − t) − surface(x(t), y(t)) over t ∈ [0, t_end] where the
    /// segment from `eye` to `target` lies over the dataset (∞ where it never does): on the
    /// Earth, the straight segment dips below the line between its ends' heights by the sag
    /// (`sag_m`: L² / 2R for a horizontal length L; 0 on the flat sheet).
    pub(super) fn min_clearance_m(
        &self,
        eye: DVec3,
        target: DVec3,
        t_end: f64,
        sag_m: f64,
        stop: bool,
    ) -> f64 {
        if self.size[0] < 2 || self.size[1] < 2 {
            return f64::INFINITY;
        }
        let s = self.spacing_m;
        let d = target - eye;
        let extent = self.size.map(|n| f64::from(n - 1) * s);
        // Clip t to the height rectangle (Liang–Barsky).
        let (mut t0, mut t1) = (0.0f64, t_end);
        for (p, dp, hi) in [(eye.x, d.x, extent[0]), (eye.y, d.y, extent[1])] {
            if dp == 0.0 {
                if !(p >= 0.0 && p <= hi) {
                    return f64::INFINITY;
                }
            } else {
                let (a, b) = (-p / dp, (hi - p) / dp);
                (t0, t1) = (t0.max(a.min(b)), t1.min(a.max(b)));
            }
        }
        if t0 > t1 {
            return f64::INFINITY;
        }
        // Grid lines crossed, per axis: the next line's index, its step, and the t it is met at.
        let at = |t: f64| eye + d * t;
        let start = at(t0);
        let line = |p: f64, dp: f64| -> (f64, f64) {
            match dp.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Greater) => ((p / s).floor() + 1.0, 1.0),
                Some(std::cmp::Ordering::Less) => ((p / s).ceil() - 1.0, -1.0),
                _ => (0.0, 0.0),
            }
        };
        let crossing = |k: f64, step: f64, p: f64, dp: f64| {
            if step == 0.0 { f64::INFINITY } else { (k * s - p) / dp }
        };
        let (mut kx, step_x) = line(start.x, d.x);
        let (mut ky, step_y) = line(start.y, d.y);
        let (du, dv) = (d.x / s, d.y / s);
        let mut least = f64::INFINITY;
        let mut ta = t0;
        loop {
            let tx = crossing(kx, step_x, eye.x, d.x);
            let ty = crossing(ky, step_y, eye.y, d.y);
            let tb = tx.min(ty).min(t1).max(ta);
            // The cell of this stretch (between two crossings: one cell), from its middle.
            let mid = at(0.5 * (ta + tb));
            let ((i, _), (j, _)) = (self.cell(mid.x, 0), self.cell(mid.y, 1));
            let corners = self.corners(i, j);
            let pa = at(ta);
            let (ua, va) = (pa.x / s - f64::from(i), pa.y / s - f64::from(j));
            // Along the stretch, τ = t − ta, the segment is at pa.z + d.z·τ and over (ua + du·τ,
            // va + dv·τ) of the cell, whose drawn ground is planar on each side of the diagonal:
            // the clearance is piecewise linear, least at an end or where the diagonal is crossed.
            let line =
                |tau: f64| pa.z + d.z * tau - drawn_height([i, j], corners, [ua + du * tau, va + dv * tau]).0;
            let sag = |tau: f64| sag_m * (ta + tau) * (1.0 - ta - tau);
            let clearance = |tau: f64| line(tau) - sag(tau);
            let length = tb - ta;
            // Where u = v (rising) or u + v = 1 (falling); NaN or ∞ along the diagonal or parallel to it.
            let diagonal =
                if diagonal_rises([i, j]) { (va - ua) / (du - dv) } else { (1.0 - ua - va) / (du + dv) };
            let mut low = clearance(0.0).min(clearance(length));
            let mut pieces = [(0.0, length), (length, length)];
            if diagonal > 0.0 && diagonal < length {
                low = low.min(clearance(diagonal));
                pieces = [(0.0, diagonal), (diagonal, length)];
            }
            // With a sag the clearance is a convex parabola on each planar piece: least at its
            // vertex where that lies inside (line' = sag_m (1 − 2t)).
            if sag_m > 0.0 {
                for (a, b) in pieces.into_iter().filter(|(a, b)| b > a) {
                    let slope = (line(b) - line(a)) / (b - a);
                    let vertex = 0.5 * (1.0 - slope / sag_m) - ta;
                    if vertex > a && vertex < b {
                        low = low.min(clearance(vertex));
                    }
                }
            }
            least = least.min(low);
            if (stop && least < 0.0) || tb >= t1 {
                return least;
            }
            if tx <= ty {
                kx += step_x;
            } else {
                ky += step_y;
            }
            ta = tb;
        }
    }
}

/// The level-1 land-cover tiles under a region, decoded once.
pub(super) struct LandcoverTiles {
    /// (texel_m of level 1, half a height spacing, level-1 size); none without land cover.
    grid: Option<(f64, f64, [u32; 2])>,
    tile: u32,
    extent: u32,
    tiles: HashMap<[u32; 2], Vec<u32>>,
}

impl LandcoverTiles {
    pub(super) fn load(dataset: &Dataset, min_m: [f64; 2], max_m: [f64; 2]) -> Result<Self, PackError> {
        let (Some(layer), Some(meta)) = (&dataset.landcover, &dataset.manifest.landcover) else {
            return Ok(Self { grid: None, tile: 1, extent: 1, tiles: HashMap::new() });
        };
        let pyramid = &layer.pyramid;
        let grid = (2.0 * meta.layer.texel_m, 0.5 * dataset.manifest.height.spacing_m, pyramid.size_at(1));
        let mut tiles = Self {
            grid: Some(grid),
            tile: pyramid.tile,
            extent: pyramid.tile_extent(),
            tiles: HashMap::new(),
        };
        let (lo, hi) = (tiles.texel(DVec2::from(min_m)), tiles.texel(DVec2::from(max_m)));
        for ty in lo[1] / pyramid.tile..=hi[1] / pyramid.tile {
            for tx in lo[0] / pyramid.tile..=hi[0] / pyramid.tile {
                let words = dataset.landcover_words(TileId::new(LCC_SOURCE_LEVEL, tx, ty))?;
                tiles.tiles.insert([tx, ty], words);
            }
        }
        Ok(tiles)
    }

    /// Whether grid points `a` and `b` lie in the same level-1 texel.
    pub(super) fn same_texel(&self, a: DVec2, b: DVec2) -> bool {
        self.texel(a) == self.texel(b)
    }

    /// A level-1 texel's edge, metres (1 without land cover).
    pub(super) fn texel_m(&self) -> f64 {
        self.grid.map_or(1.0, |(texel_m, ..)| texel_m)
    }

    /// The level-1 texel holding grid point `p`, clamped to the layer.
    fn texel(&self, p: DVec2) -> [u32; 2] {
        let Some((texel_m, half_spacing_m, size)) = self.grid else { return [0; 2] };
        let q = [p.x, p.y].map(|v| ((v + half_spacing_m) / texel_m).floor().max(0.0) as u64);
        [0, 1].map(|a| q[a].min(u64::from(size[a] - 1)) as u32)
    }

    /// Palette index of the land cover at `p` (0, bare, without land cover).
    pub(super) fn index(&self, dataset: &Dataset, p: DVec2) -> Result<u32, PackError> {
        if self.grid.is_none() {
            return Ok(crate::dataset::lcc::LCC_BARE_INDEX);
        }
        let q = LccCoding::texel_of(LCC_SOURCE_LEVEL, self.texel(p));
        let Some(words) = self.tiles.get(&q.map(|v| v / self.tile)) else {
            return dataset.landcover_index(LCC_SOURCE_LEVEL, q);
        };
        let local = q.map(|v| v % self.tile);
        let word = words[(local[1] * self.extent + local[0]) as usize];
        Ok(dataset.lcc_coding().map_or(word, |coding| coding.decode(LCC_SOURCE_LEVEL, word, q)))
    }
}
