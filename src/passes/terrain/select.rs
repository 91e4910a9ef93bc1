//! How it works: CDLOD node selection (Strugar 2010) over the height pyramid, on the CPU.
//!
//! A node of LOD `m` is a `cells`² grid whose vertices are the samples of height level `m`, so
//! one height tile holds `(HEIGHT_TILE_CELLS / cells)`² nodes of its level. Each LOD owns a ring of
//! distances: LOD `m` is used up to `range[m]` from the camera, chosen so that a triangle edge at
//! the ring's far end covers `triangle_px` pixels. Walking down from the coarsest nodes, a node is
//! drawn as is when its box lies beyond the finer LOD's range, and split otherwise; quadrants whose
//! child would lie outside the finer range are drawn by the parent (a quadrant mask), exactly as
//! Strugar does. Morphing starts at `morph_start[m]` and completes at `range[m]`, where the coarser
//! LOD takes over, which is what keeps neighbouring LODs crack-free. On the Earth a node is also
//! split, whatever its ring, while its mapping would misplace its ground by more than
//! `terrain.placing_miss_px` pixels (only nodes hundreds of kilometres across, seen from high up).

use std::collections::HashMap;

use glam::DVec3;

use crate::camera::{Camera, Frustum};
use crate::config::TerrainSettings;
use crate::dataset::{Dataset, HEIGHT_BORDER, HEIGHT_TILE_CELLS, Pyramid, TileId};
use crate::earth::placing::PlacedView;

/// A node of the terrain quadtree: LOD `lod`, position (`x`, `y`) in nodes of that LOD.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId {
    /// Its LOD: 0 the finest, whose vertices are level-0 height samples.
    pub lod: u32,
    /// Column, in nodes of that LOD east of grid space's origin.
    pub x: u32,
    /// Row, in nodes of that LOD north of grid space's origin.
    pub y: u32,
}

/// A node to draw and which of its quadrants (bit `qy * 2 + qx`, south-west first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Selected {
    /// The node drawn.
    pub node: NodeId,
    /// The quadrants it draws itself (bits as above); its finer children draw the others.
    pub quadrants: u8,
}

/// `Selected::quadrants` of a node drawn whole.
pub const ALL_QUADRANTS: u8 = 0b1111;

/// The geometry of the node quadtree and its LOD rings.
#[derive(Debug, Clone)]
pub struct Lods {
    /// Grid cells along a node's side (`terrain.node_cells`), the same at every LOD.
    pub cells: u32,
    /// Level-0 height sample spacing, metres: a LOD-0 cell's edge.
    pub spacing_m: f64,
    /// The height pyramid: one LOD per level.
    pub pyramid: Pyramid,
    /// Per LOD: distance up to which it is drawn, and where its morph starts, metres.
    pub range_m: Vec<f64>,
    /// Per LOD: distance at which its vertices start morphing towards the coarser LOD, metres.
    pub morph_start_m: Vec<f64>,
    /// The most a node's mapping may misplace what it draws at 1 m from the camera, metres
    /// (`terrain.placing_miss_px` pixels): a node whose polynomial would miss by more at its
    /// distance (`PlacedView::miss_bound_m`) is split, even beyond its finer LOD's ring (its
    /// children then draw fully morphed: the coarser LOD's triangles, each placed by a mapping of
    /// half the size, an eighth the miss). On a 60° view 1,080 pixels tall it matters only where
    /// a ring's nodes grow hundreds of kilometres across, past about 1,000 km.
    pub placing_miss_at_1m: f64,
}

impl Lods {
    /// Rings for a view whose pixel at distance `d` covers `d * metres_per_pixel_at_1m` metres.
    pub fn new(
        pyramid: Pyramid,
        spacing_m: f64,
        cells: u32,
        metres_per_pixel_at_1m: f64,
        triangle_px: f64,
        morph_fraction: f64,
        placing_miss_px: f64,
    ) -> Self {
        let levels = pyramid.levels;
        let range_m: Vec<f64> = (0..levels)
            .map(|lod| {
                let cell_m = spacing_m * f64::from(1u32 << lod);
                let node_m = cell_m * f64::from(cells);
                if lod + 1 == levels {
                    return f64::INFINITY;
                }
                // A triangle edge covers `triangle_px` pixels at the ring's end; the ring must also
                // span a node diagonal and a half, so LODs of neighbouring nodes differ by one at most.
                (cell_m / (triangle_px * metres_per_pixel_at_1m)).max(2.2 * node_m)
            })
            .collect();
        let morph_start_m = (0..levels as usize)
            .map(|lod| {
                let inner = if lod == 0 { 0.0 } else { range_m[lod - 1] };
                if range_m[lod].is_infinite() {
                    f64::INFINITY
                } else {
                    (range_m[lod] * (1.0 - morph_fraction)).max(inner)
                }
            })
            .collect();
        let placing_miss_at_1m = placing_miss_px * metres_per_pixel_at_1m;
        Self { cells, spacing_m, pyramid, range_m, morph_start_m, placing_miss_at_1m }
    }

    /// The rings of `dataset`'s terrain for `camera` in a viewport `height_px` tall, as the
    /// terrain settings ask.
    pub fn for_view(dataset: &Dataset, settings: &TerrainSettings, camera: &Camera, height_px: u32) -> Self {
        Self::new(
            dataset.height.pyramid,
            dataset.manifest.height.spacing_m,
            settings.node_cells,
            camera.metres_per_pixel(1.0, height_px),
            settings.triangle_px,
            settings.morph_fraction,
            settings.placing_miss_px,
        )
    }

    /// Edge of a node of LOD `lod`, metres.
    pub fn node_m(&self, lod: u32) -> f64 {
        self.spacing_m * f64::from(1u32 << lod) * f64::from(self.cells)
    }

    /// Grid cells of LOD `lod` along each axis (samples − 1).
    pub fn steps(&self, lod: u32) -> [u32; 2] {
        self.pyramid.size_at(lod).map(|n| n.saturating_sub(1).max(1))
    }

    /// Nodes of LOD `lod` along each axis needed to cover the dataset (the last may be partly outside).
    pub fn nodes_at(&self, lod: u32) -> [u32; 2] {
        self.steps(lod).map(|n| n.div_ceil(self.cells))
    }

    fn nodes_per_tile(&self) -> u32 {
        HEIGHT_TILE_CELLS / self.cells
    }

    /// The height tile that holds `node`'s samples.
    pub fn tile_of(&self, node: NodeId) -> TileId {
        let per = self.nodes_per_tile();
        TileId::new(node.lod, node.x / per, node.y / per)
    }

    /// Sample (border included) of `node`'s south-west vertex within its tile.
    pub fn sample_offset(&self, node: NodeId) -> [u32; 2] {
        let per = self.nodes_per_tile();
        [node.x % per, node.y % per].map(|n| n * self.cells + HEIGHT_BORDER)
    }

    /// Sample position (border included) of `node`'s south-west vertex within `source`, its own
    /// tile or an ancestor of it, where one node cell spans 1/2^k samples (k levels up).
    pub fn sample_offset_in(&self, node: NodeId, source: TileId) -> [f32; 2] {
        let k = source.level - node.lod;
        let in_level = |n: u32, tile: u32| {
            f64::from(n * self.cells) / f64::from(1u32 << k) - f64::from(tile * HEIGHT_TILE_CELLS)
        };
        [in_level(node.x, source.x), in_level(node.y, source.y)]
            .map(|v| (v + f64::from(HEIGHT_BORDER)) as f32)
    }

    /// Cells of `node` inside the dataset along each axis (the rest of its grid is clamped).
    pub fn cells_inside(&self, node: NodeId) -> [u32; 2] {
        let steps = self.steps(node.lod);
        let start = [node.x, node.y].map(|n| n * self.cells);
        [0, 1].map(|a| steps[a].saturating_sub(start[a]).min(self.cells))
    }

    /// Grid-space box of `node` (metres), with its height range.
    fn node_box(&self, node: NodeId, height_m: [f32; 2]) -> (DVec3, DVec3) {
        let size = self.node_m(node.lod);
        let inside =
            self.cells_inside(node).map(|c| f64::from(c) * self.spacing_m * f64::from(1u32 << node.lod));
        let min = DVec3::new(f64::from(node.x) * size, f64::from(node.y) * size, f64::from(height_m[0]));
        (min, DVec3::new(min.x + inside[0], min.y + inside[1], f64::from(height_m[1])))
    }
}

fn distance_to_box(p: DVec3, (min, max): (DVec3, DVec3)) -> f64 {
    (p.clamp(min, max) - p).length()
}

/// Selects the nodes to draw for the camera `placed` sees from. `frustum` is in camera-relative
/// space: a node is culled by the box that holds what it draws (`PlacedView::box_rel_m`: on the
/// Earth, bent), its LOD chosen by its distance on the flat sheet (as the shader's morph measures
/// it; the bend changes a distance by less than the drop over it, 785 m in 100 km), and split
/// further where its mapping would misplace its ground by more than `Lods::placing_miss_at_1m`
/// allows. `bounds` gives a node's height range. With `horizon` (the dataset's lowest ground,
/// metres), a node the Earth hides from the camera is culled too (`PlacedView::hidden_by_earth`).
pub fn select(
    lods: &Lods,
    placed: &mut PlacedView,
    frustum: &Frustum,
    horizon: Option<f64>,
    bounds: &mut dyn FnMut(NodeId) -> [f32; 2],
) -> Vec<Selected> {
    let mut out = Vec::new();
    let camera_grid_m = placed.camera_grid_m();
    let mut search = Search { lods, camera: camera_grid_m, placed, frustum, horizon, bounds };
    let top = lods.pyramid.levels - 1;
    let [nx, ny] = lods.nodes_at(top);
    for y in 0..ny {
        for x in 0..nx {
            search.visit(NodeId { lod: top, x, y }, false, &mut out);
        }
    }
    out
}

/// One selection's walk down the quadtree.
struct Search<'a, 'p> {
    lods: &'a Lods,
    camera: DVec3,
    placed: &'a mut PlacedView<'p>,
    frustum: &'a Frustum,
    horizon: Option<f64>,
    bounds: &'a mut dyn FnMut(NodeId) -> [f32; 2],
}

impl Search<'_, '_> {
    /// Returns false when `node` lies beyond its own range: its parent draws that area instead.
    /// A node `placing_split` from its parent is drawn even there (its parent's mapping misses).
    fn visit(&mut self, node: NodeId, placing_split: bool, out: &mut Vec<Selected>) -> bool {
        let lods = self.lods;
        let (min, max) = lods.node_box(node, (self.bounds)(node));
        let distance_m = distance_to_box(self.camera, (min, max));
        if !placing_split && distance_m > lods.range_m[node.lod as usize] {
            return false;
        }
        let (lo, hi) = self.placed.box_rel_m(min, max);
        if !self.frustum.intersects_box(lo, hi)
            || self.horizon.is_some_and(|h| self.placed.hidden_by_earth(lo, hi, h))
        {
            return true;
        }
        let misplaced = self.placed.miss_bound_m(min, max) > lods.placing_miss_at_1m * distance_m;
        if node.lod == 0 || (distance_m > lods.range_m[node.lod as usize - 1] && !misplaced) {
            out.push(Selected { node, quadrants: ALL_QUADRANTS });
            return true;
        }
        let [nx, ny] = lods.nodes_at(node.lod - 1);
        let mut parent_draws = 0u8;
        for q in 0..4u8 {
            let child = NodeId {
                lod: node.lod - 1,
                x: node.x * 2 + u32::from(q & 1),
                y: node.y * 2 + u32::from(q >> 1),
            };
            if child.x >= nx || child.y >= ny {
                continue;
            }
            if !self.visit(child, misplaced, out) {
                parent_draws |= 1 << q;
            }
        }
        if parent_draws != 0 {
            out.push(Selected { node, quadrants: parent_draws });
        }
        true
    }
}

/// Height ranges of nodes, computed once per node from its tile's samples.
pub struct NodeBounds {
    known: HashMap<NodeId, [f32; 2]>,
    /// Used for nodes whose tile cannot be read: the whole dataset's range.
    fallback_m: [f32; 2],
}

impl NodeBounds {
    /// No range known yet; nodes whose tile cannot be read get `fallback_m` (min, max), metres.
    pub fn new(fallback_m: [f32; 2]) -> Self {
        Self { known: HashMap::new(), fallback_m }
    }

    /// The node's height range; `tile` gives the samples of the node's height tile.
    pub fn get<S: std::ops::Deref<Target = [f32]>>(
        &mut self,
        lods: &Lods,
        node: NodeId,
        tile: impl FnOnce(TileId) -> Option<S>,
    ) -> [f32; 2] {
        if let Some(&range) = self.known.get(&node) {
            return range;
        }
        let Some(samples) = tile(lods.tile_of(node)) else {
            return self.fallback_m;
        };
        let extent = lods.pyramid.tile_extent() as usize;
        let [x0, y0] = lods.sample_offset(node).map(|v| v as usize);
        let [cx, cy] = lods.cells_inside(node).map(|c| c as usize);
        let mut range = [f32::INFINITY, f32::NEG_INFINITY];
        for row in samples.chunks_exact(extent).skip(y0).take(cy + 1) {
            for &h in &row[x0..=(x0 + cx).min(extent - 1)] {
                range = [range[0].min(h), range[1].max(h)];
            }
        }
        self.known.insert(node, range);
        range
    }
}
