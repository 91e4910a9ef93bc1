//! How it works: the geometry of the Tile Load Map's camera-centred rings, in f64 (see the
//! pass's module): which square of ground each cell covers, the global address of a cell, and the
//! per-column / per-row spans the GPU pass and its twin combine.

use glam::DVec3;

use crate::config::TlmSettings;
use crate::dataset::{HEIGHT_TILE_CELLS, Pyramid};
use crate::gpu::gpu_types::TlmSpan;
use crate::gpu::layout::{TLM_MAX_RINGS, TLM_SPAN_COVERED, TLM_SPAN_INSIDE, TileSpan};

/// The rings of one frame, in grid space (f64).
#[derive(Debug, Clone, PartialEq)]
pub struct TlmLayout {
    /// Rings used: as many as cover the dataset from the camera, at most `tlm.max_rings`.
    pub rings: u32,
    /// Cells per ring side.
    pub cells: u32,
    /// Edge of a ring-0 cell, metres.
    pub cell_m: f64,
    /// Per ring: global address of its south-west cell, in cells of that ring (both even).
    pub origin_cell: Vec<[i64; 2]>,
    /// The dataset's height samples span [min, max] of grid space, metres.
    pub dataset_min_m: [f64; 2],
    /// The north-east end of that span, metres.
    pub dataset_max_m: [f64; 2],
}

/// A cell's global address: ring and position in cells of that ring, from the grid origin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CellAddress {
    /// Its ring: 0 innermost, cells of edge `cell_m · 2^ring`.
    pub ring: u32,
    /// Column, in cells of that ring east of grid space's origin.
    pub x: i64,
    /// Row, in cells of that ring north of grid space's origin.
    pub y: i64,
}

impl TlmLayout {
    /// The grid-space rectangle of a dataset's height samples.
    pub fn dataset_rect_m(pyramid: &Pyramid, spacing_m: f64) -> ([f64; 2], [f64; 2]) {
        ([0.0, 0.0], pyramid.size.map(|n| f64::from(n.saturating_sub(1).max(1)) * spacing_m))
    }

    /// The rings around a camera at `camera_grid_m` (grid space, metres).
    pub fn new(settings: &TlmSettings, dataset_m: ([f64; 2], [f64; 2]), camera_grid_m: [f64; 2]) -> Self {
        let (min, max) = dataset_m;
        let cells = settings.cells;
        let mut origin_cell = Vec::new();
        for ring in 0..settings.max_rings.clamp(1, TLM_MAX_RINGS) {
            let c = settings.cell_m * f64::from(1u32 << ring);
            // Centred on the camera, snapped to an even cell: the ring moves two cells at a time,
            // so the inner ring's edges always fall on this ring's cell edges.
            let origin = camera_grid_m.map(|v| 2 * ((v / c - f64::from(cells / 2)) / 2.0).round() as i64);
            origin_cell.push(origin);
            let covers = (0..2).all(|a| {
                origin[a] as f64 * c <= min[a] && (origin[a] + i64::from(cells)) as f64 * c >= max[a]
            });
            if covers {
                break;
            }
        }
        Self {
            rings: origin_cell.len() as u32,
            cells,
            cell_m: settings.cell_m,
            origin_cell,
            dataset_min_m: min,
            dataset_max_m: max,
        }
    }

    /// Cell edge of `ring`, metres.
    pub fn ring_cell_m(&self, ring: u32) -> f64 {
        self.cell_m * f64::from(1u32 << ring)
    }

    /// Grid-space south-west corner of `ring`, metres.
    pub fn ring_origin_m(&self, ring: u32) -> [f64; 2] {
        let c = self.ring_cell_m(ring);
        self.origin_cell[ring as usize].map(|g| g as f64 * c)
    }

    /// Grid-space rectangle (min, max) of cell (`cx`, `cy`) of `ring`, metres (not clamped).
    pub fn cell_rect_m(&self, ring: u32, cx: u32, cy: u32) -> ([f64; 2], [f64; 2]) {
        let c = self.ring_cell_m(ring);
        let a = self.global_address(ring, cx, cy);
        ([a.x as f64 * c, a.y as f64 * c], [(a.x + 1) as f64 * c, (a.y + 1) as f64 * c])
    }

    /// The global address of cell (`cx`, `cy`) of `ring`: the same square of ground whichever
    /// frame's layout names it.
    pub fn global_address(&self, ring: u32, cx: u32, cy: u32) -> CellAddress {
        let [x, y] = self.origin_cell[ring as usize];
        CellAddress { ring, x: x + i64::from(cx), y: y + i64::from(cy) }
    }

    /// Position of cell (`cx`, `cy`) of `ring` in the TLM buffer.
    pub fn index(&self, ring: u32, cx: u32, cy: u32) -> usize {
        ((ring * self.cells + cy) * self.cells + cx) as usize
    }

    /// (ring, cx, cy) of buffer position `index`.
    pub fn cell_of(&self, index: usize) -> (u32, u32, u32) {
        let n = self.cells as usize;
        ((index / (n * n)) as u32, (index % n) as u32, (index / n % n) as u32)
    }

    /// Cells of the TLM buffer this frame.
    pub fn cell_count(&self) -> usize {
        (self.rings * self.cells * self.cells) as usize
    }

    /// True when ring `ring − 1` speaks for this cell.
    pub fn is_covered(&self, ring: u32, cx: u32, cy: u32) -> bool {
        ring > 0 && self.axis_covered(ring, 0, cx) && self.axis_covered(ring, 1, cy)
    }

    fn axis_covered(&self, ring: u32, axis: usize, i: u32) -> bool {
        let g = self.origin_cell[ring as usize][axis] + i64::from(i);
        let inner = self.origin_cell[ring as usize - 1][axis];
        2 * g >= inner && 2 * g + 2 <= inner + i64::from(self.cells)
    }

    /// The innermost uncovered cell (ring, cx, cy) holding grid-space point `p_m`, if any ring does.
    pub fn locate(&self, p_m: [f64; 2]) -> Option<(u32, u32, u32)> {
        (0..self.rings).find_map(|ring| {
            let (o, c) = (self.ring_origin_m(ring), self.ring_cell_m(ring));
            let [cx, cy] = [0, 1].map(|a| ((p_m[a] - o[a]) / c).floor());
            let inside = [cx, cy].iter().all(|&v| v >= 0.0 && v < f64::from(self.cells));
            inside.then_some((ring, cx as u32, cy as u32))
        })
    }

    /// Columns then rows of every ring (`(ring · 2 + axis) · cells + i`), relative to the camera.
    pub fn spans(&self, pyramid: &Pyramid, spacing_m: f64, camera_grid_m: DVec3) -> Vec<TlmSpan> {
        let camera = [camera_grid_m.x, camera_grid_m.y];
        let mut spans = Vec::with_capacity((self.rings * 2 * self.cells) as usize);
        for ring in 0..self.rings {
            let c = self.ring_cell_m(ring);
            let level = height_level(pyramid, spacing_m, c);
            let tile_m = f64::from(HEIGHT_TILE_CELLS) * spacing_m * f64::from(1u32 << level);
            let tiles = pyramid.tiles_at(level);
            for axis in 0..2 {
                for i in 0..self.cells {
                    let g = self.origin_cell[ring as usize][axis] + i64::from(i);
                    let (lo, hi) = (g as f64 * c, (g + 1) as f64 * c);
                    let (min, max) = (self.dataset_min_m[axis], self.dataset_max_m[axis]);
                    let mut span = TlmSpan::default();
                    if ring > 0 && self.axis_covered(ring, axis, i) {
                        span.flags |= TLM_SPAN_COVERED;
                    }
                    if lo < max && hi > min {
                        let (lo, hi) = (lo.max(min), hi.min(max));
                        span.flags |= TLM_SPAN_INSIDE;
                        span.rel_m = [(lo - camera[axis]) as f32, (hi - camera[axis]) as f32];
                        // Tiles share their edge samples: one touching only at an edge adds nothing.
                        let last_tile = f64::from(tiles[axis] - 1);
                        let first = (lo / tile_m).floor().clamp(0.0, last_tile);
                        let last = ((hi / tile_m).ceil() - 1.0).clamp(first, last_tile);
                        span.height_tiles = TileSpan { first: first as u32, last: last as u32 }.pack();
                    }
                    spans.push(span);
                }
            }
        }
        spans
    }
}

/// The finest height level whose tiles are at least `cell_m` wide (so a cell overlaps at most
/// 2 × 2 of them), or the coarsest.
pub(super) fn height_level(pyramid: &Pyramid, spacing_m: f64, cell_m: f64) -> u32 {
    let tile_m = |level: u32| f64::from(HEIGHT_TILE_CELLS) * spacing_m * f64::from(1u32 << level);
    (0..pyramid.levels).find(|&level| tile_m(level) >= cell_m).unwrap_or(pyramid.levels - 1)
}
