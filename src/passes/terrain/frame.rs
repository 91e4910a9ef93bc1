//! The terrain pass's CPU half: the node instances of a frame (`node_batches`), the uniforms both
//! terrain passes read (`terrain_uniforms`), the height tiles the selected nodes need
//! (`height_tiles`), and the grid's index layout (`grid_indices`).

use std::ops::Range;

use glam::DVec3;

use crate::config::Settings;
use crate::dataset::surface::diagonal_rises;
use crate::dataset::{Dataset, ImageryFormat, TileId};
use crate::earth::placing::PlacedView;
use crate::gpu::gpu_types::{EarthNode, TerrainNode, TerrainUniforms};
use crate::gpu::layout::{IMAGERY_NONE, IMAGERY_PUNCHED, IMAGERY_STRAIGHT, IMAGERY_VEGETATION, MAX_LEVELS};
use crate::light::CloudShadowFrame;
use crate::streaming::{TileCache, page_levels};

use super::select::{Lods, NodeId, Selected};

/// Node instances of one frame, grouped by quadrant.
#[derive(Default)]
pub struct NodeBatches {
    /// Each quadrant's instances (south-west, south-east, north-west, north-east: the grid's index
    /// ranges' order); a node drawing several quadrants appears in each.
    pub by_quadrant: [Vec<TerrainNode>; 4],
    /// Each of those instances' Earth mapping (origin the node's centre at height 0), in the same
    /// order.
    pub earth: [Vec<EarthNode>; 4],
    /// The box each of those instances draws (its quadrant of the node), in the same order.
    pub boxes: [Vec<QuadrantBox>; 4],
    /// Where each of those instances' node lies and the height tile it reads, in the same order:
    /// what the CPU needs to rebuild the drawn ground (`reference::terrain`).
    pub sources: [Vec<NodeSource>; 4],
}

/// A drawn node's south-west corner in the grid and the height tile it reads (its own, or its
/// finest resident ancestor).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeSource {
    /// The corner, metres (the GPU sees it camera-relative, in f32).
    pub origin_grid_m: glam::DVec2,
    /// The tile.
    pub tile: TileId,
}

/// The grid-space box of one node quadrant's ground, metres: what the texcells over it stand in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadrantBox {
    /// South-west-bottom corner.
    pub min_m: DVec3,
    /// North-east-top corner.
    pub max_m: DVec3,
}

impl QuadrantBox {
    /// The distance from `point_m` to the box's nearest point (0 inside).
    pub fn distance_m(&self, point_m: DVec3) -> f64 {
        (self.min_m - point_m).max(point_m - self.max_m).max(DVec3::ZERO).length()
    }

    /// The distance from `point_m` to the box's farthest corner.
    pub fn farthest_m(&self, point_m: DVec3) -> f64 {
        (point_m - self.min_m).abs().max((self.max_m - point_m).abs()).length()
    }
}

impl NodeBatches {
    /// Instances over all quadrants: one draw instance each, so a node may count up to four times.
    pub fn len(&self) -> usize {
        self.by_quadrant.iter().map(Vec::len).sum()
    }

    /// No quadrant has an instance: the frame draws no terrain.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The frame's light: towards the sun (unit, in the camera-relative world: `sun::frame_sun_dir`).
/// What reaches the ground of it, and of the sky, is the air's (`shared/air.wgsl`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameLight {
    /// Towards the sun.
    pub sun_dir: DVec3,
}

/// The terrain passes' uniforms for a camera at `camera_grid_m` (grid space) with `clip` the
/// clip-from-camera-relative-world matrix, in `light`, at the scene's time `time_s` (the clouds'
/// drift), over ground falling away from the camera by `fall_per_m2` d²
/// (`earth::horizon::fall_per_m2`, 0 flat).
pub fn terrain_uniforms(
    dataset: &Dataset,
    settings: &Settings,
    camera_grid_m: DVec3,
    clip: glam::Mat4,
    light: FrameLight,
    time_s: f64,
    fall_per_m2: f64,
) -> TerrainUniforms {
    let manifest = &dataset.manifest;
    let sun = light.sun_dir;
    let half_spacing = 0.5 * manifest.height.spacing_m;
    let clouds =
        CloudShadowFrame::new(&settings.clouds, sun, manifest.height.max_m as f64, camera_grid_m, time_s)
            .on_earth(fall_per_m2);
    let mut uniforms = TerrainUniforms {
        clip_from_view_world: clip.to_cols_array_2d(),
        sun_dir: sun.as_vec3().extend(0.0).to_array(),
        camera_grid_m: camera_grid_m.as_vec3().extend(0.0).to_array(),
        height_range_m: [manifest.height.min_m, manifest.height.max_m],
        node_cells: settings.terrain.node_cells,
        imagery_texels: match &dataset.imagery {
            None => IMAGERY_NONE,
            Some(layer) if layer.block_format.is_some_and(ImageryFormat::holes_are_transparent) => {
                IMAGERY_PUNCHED
            }
            Some(_) if manifest.vegetation.is_some() => IMAGERY_VEGETATION,
            Some(_) => IMAGERY_STRAIGHT,
        },
        vegetation: settings.seeds.vegetation_ramp(),
        imagery_frame: [0.0; 4],
        cloud_field: clouds.field,
        cloud_shift: clouds.shift,
        imagery_levels: [[0; 4]; MAX_LEVELS as usize],
        imagery_level_count: 1,
        _pad: 0,
    };
    if let (Some(layer), Some(meta)) = (&dataset.imagery, &manifest.imagery) {
        let p = &layer.pyramid;
        uniforms.imagery_frame = [
            -half_spacing as f32,
            -half_spacing as f32,
            meta.texel_m as f32,
            settings.imagery.lod_bias as f32,
        ];
        uniforms.imagery_levels = page_levels(p);
        uniforms.imagery_level_count = p.levels;
    }
    uniforms
}

/// The instances drawing `selected` from the camera `placed` sees from. A node reads its
/// own height tile, or while that streams in, its finest resident ancestor; a node with neither
/// (only before the pinned levels load) is dropped and counted. `bounds` gives node height ranges
/// (the skirt depth). Nodes on the dataset's boundary hang their skirts down to `floor_m`, the
/// dataset's lowest ground (the shader stops every skirt a cell below it): seen from outside, from
/// below the edge's ground, the terrain is then a solid block, not a shell showing its underside.
pub fn node_batches(
    lods: &Lods,
    selected: &[Selected],
    placed: &mut PlacedView,
    heights: &TileCache,
    floor_m: f32,
    bounds: &mut dyn FnMut(NodeId) -> [f32; 2],
) -> (NodeBatches, usize) {
    let mut batches = NodeBatches::default();
    let mut dropped = 0;
    let camera_grid_m = placed.camera_grid_m();
    for s in selected {
        let Some((source, slot)) = heights.resident_ancestor(lods.tile_of(s.node)) else {
            dropped += 1;
            continue;
        };
        let size = lods.node_m(s.node.lod);
        let cell_m = size / f64::from(lods.cells);
        let [low_m, high_m] = bounds(s.node);
        let (steps, inside) = (lods.steps(s.node.lod), lods.cells_inside(s.node));
        let start = [s.node.x, s.node.y].map(|n| n * lods.cells);
        let boundary = (0..2).any(|a| start[a] == 0 || start[a] + inside[a] >= steps[a]);
        let low_m = if boundary { low_m.min(floor_m) } else { low_m };
        let lod = s.node.lod as usize;
        let node = TerrainNode {
            // Subtracted in f64: the GPU only sees offsets from the camera.
            origin_rel_m: [
                (f64::from(s.node.x) * size - camera_grid_m.x) as f32,
                (f64::from(s.node.y) * size - camera_grid_m.y) as f32,
            ],
            cell_m: cell_m as f32,
            height_slot: slot,
            sample_offset: lods.sample_offset_in(s.node, source),
            morph_start_m: lods.morph_start_m[lod].min(f64::from(f32::MAX)) as f32,
            morph_end_m: lods.range_m[lod].min(f64::from(f32::MAX)) as f32,
            cells_inside: lods.cells_inside(s.node).map(|c| c as f32),
            sample_step: 1.0 / (1u32 << (source.level - s.node.lod)) as f32,
            // Deep enough to close any seam against a neighbour reading another level.
            skirt_m: (f64::from(high_m - low_m) + cell_m) as f32,
        };
        let origin = [f64::from(s.node.x) * size, f64::from(s.node.y) * size];
        let earth = placed.node(DVec3::new(origin[0] + 0.5 * size, origin[1] + 0.5 * size, 0.0));
        let half_cells = f64::from(lods.cells / 2);
        for q in 0..4 {
            if s.quadrants & (1 << q) == 0 {
                continue;
            }
            batches.by_quadrant[q].push(node);
            batches.earth[q].push(earth);
            batches.sources[q].push(NodeSource { origin_grid_m: origin.into(), tile: source });
            // The quadrant's cells, cut to the node's cells inside the dataset.
            let first = [(q & 1) as f64 * half_cells, (q >> 1) as f64 * half_cells];
            let last = [0, 1].map(|a| (first[a] + half_cells).min(f64::from(inside[a])).max(first[a]));
            batches.boxes[q].push(QuadrantBox {
                min_m: DVec3::new(
                    origin[0] + first[0] * cell_m,
                    origin[1] + first[1] * cell_m,
                    f64::from(low_m),
                ),
                max_m: DVec3::new(
                    origin[0] + last[0] * cell_m,
                    origin[1] + last[1] * cell_m,
                    f64::from(high_m),
                ),
            });
        }
    }
    (batches, dropped)
}

/// The height tiles the selected nodes read, coarse first (they stand in for everything finer).
pub fn height_tiles(lods: &Lods, selected: &[Selected]) -> Vec<TileId> {
    let mut tiles: Vec<TileId> = selected.iter().map(|s| lods.tile_of(s.node)).collect();
    tiles.sort_by(|a, b| b.level.cmp(&a.level).then(a.cmp(b)));
    tiles.dedup();
    tiles
}

/// Triangles of a `cells`² grid ringed by skirts: `(cells + 3)²` vertices, the outer ring being
/// the skirts' lower edge. Grouped quadrant by quadrant (south-west, south-east, north-west,
/// north-east; skirts go with the quadrant they border), with each quadrant's index range. The
/// grid is counter-clockwise seen from above, each cell cut along the diagonal
/// `dataset::surface::diagonal_rises` names (the ground seeds stand on is this mesh's); skirts are
/// walls seen from either side, so they carry both windings.
pub fn grid_indices(cells: u32) -> (Vec<u32>, [Range<u32>; 4]) {
    let row = cells + 3;
    let half = cells / 2;
    // Ring cell 0 and inner cells 1..=half border the west (or south) half.
    let side = |c: u32| usize::from(c > half);
    let mut quadrants: [Vec<u32>; 4] = Default::default();
    for cj in 0..cells + 2 {
        for ci in 0..cells + 2 {
            let (sw, se, nw, ne) =
                (cj * row + ci, cj * row + ci + 1, (cj + 1) * row + ci, (cj + 1) * row + ci + 1);
            // Node cell (ci − 1, cj − 1) (the ring's wrap to u32::MAX keeps the parity). Nodes
            // start at multiples of `cells`, a power of two: a node's cell has its dataset cell's parity.
            let rises = diagonal_rises([ci.wrapping_sub(1), cj.wrapping_sub(1)]);
            let t = if rises { [sw, se, ne, sw, ne, nw] } else { [sw, se, nw, se, ne, nw] };
            let quadrant = &mut quadrants[side(cj) * 2 + side(ci)];
            quadrant.extend_from_slice(&t);
            let inner = (1..=cells).contains(&ci) && (1..=cells).contains(&cj);
            if !inner {
                quadrant.extend_from_slice(&[t[0], t[2], t[1], t[3], t[5], t[4]]);
            }
        }
    }
    let mut indices = Vec::with_capacity(quadrants.iter().map(Vec::len).sum());
    let ranges = quadrants.map(|q| {
        let start = indices.len() as u32;
        indices.extend_from_slice(&q);
        start..indices.len() as u32
    });
    (indices, ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_and_skirts_cover_every_cell_once_by_quadrant() {
        let cells = 8;
        let row = cells + 3;
        let (indices, ranges) = grid_indices(cells);
        let ring_cells = (cells + 2) * (cells + 2) - cells * cells;
        assert_eq!(indices.len() as u32, (cells * cells + 2 * ring_cells) * 6);
        assert_eq!(ranges.iter().map(|r| r.len()).sum::<usize>(), indices.len());
        assert!(indices.iter().all(|&i| i < row * row));
        // Every inner triangle is counter-clockwise from above (+z), and sits in its quadrant.
        let inner = |i: u32| (1..=cells + 1).contains(&(i % row)) && (1..=cells + 1).contains(&(i / row));
        for (q, range) in ranges.iter().enumerate() {
            for t in indices[range.start as usize..range.end as usize].chunks(3) {
                if !t.iter().all(|&i| inner(i)) {
                    continue;
                }
                let p: Vec<(i32, i32)> = t.iter().map(|&i| ((i % row) as i32, (i / row) as i32)).collect();
                let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
                assert!(area > 0, "{t:?}");
                let centre =
                    ((p[0].0 + p[1].0 + p[2].0) as f32 / 3.0, (p[0].1 + p[1].1 + p[2].1) as f32 / 3.0);
                let mid = 1.0 + (cells / 2) as f32;
                assert_eq!(q, usize::from(centre.1 > mid) * 2 + usize::from(centre.0 > mid), "{t:?}");
            }
        }
    }
}
