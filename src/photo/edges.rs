//! How it works: whether a forest's edge follows the land cover's cells as a staircase or the
//! smooth edge the data allows, judged on where the trees stand (pass 3's records), not on
//! pixels: from above a crown is as wide as a cell, and its blur hides a staircase from any pixel
//! mask while the eye still reads the cells in the stand's outline. At a point two shares of
//! trees' classes are known (`keys::Landcover`): the nearest cell's (0 or 1: the staircase) and
//! the four nearest cells' interpolated bilinearly between their centres (the filtered edge).
//! Their difference, `step = nearest − bilinear`, is the staircase's own pattern, a saw tooth along
//! every cell edge that a class boundary follows. Near an edge (the bilinear share strictly
//! between 0 and 1) the trees' mean step is compared with what each kind of edge would give:
//! - trees that follow the cells stand with a density `k · nearest`: their mean step is the
//!   area-weighted mean of `nearest · step` over `nearest`;
//! - trees whose density is the bilinear share (each seed reads its class up to half a cell away
//!   each way, uniformly: seed selection's `class_offset`): the mean of `bilinear · step` over
//!   `bilinear`.
//!
//! Both references are integrals over the view's ground near edges, taken over its pixels (their
//! ground areas, within the trees' reach); the trees' own steps are taken at their exact ground
//! points. The **step share** (observed − filtered) / (on the cells − filtered) places the edges
//! between the two, whatever the forest's density: 1 on the cells, 0 filtered. The comparison runs
//! twice: over the edges between classes that all grow seeds (the edges seed selection dithers),
//! and over every edge (shores and the data's edge, which stay on the cells, included).

use serde::Serialize;

use super::PhotoError;
use super::keys::Landcover;
use super::measure::PixelKeys;
use crate::camera::Camera;
use crate::classes::SpeciesKind;
use crate::frame::Renderer;
use crate::gpu::layout::SpeciesLod;

/// One comparison of the trees' steps with the two kinds of edge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Staircase {
    /// Pixels near an edge within the trees' reach (the references' area).
    pub pixels: usize,
    /// Trees near an edge.
    pub trees: usize,
    /// Their mean step (`None` without trees).
    pub trees_step: Option<f64>,
    /// The mean step of trees that follow the cells (`None` without pixels).
    pub on_cells_step: Option<f64>,
    /// The mean step of trees at the bilinear share's density.
    pub filtered_step: Option<f64>,
    /// Where the trees lie between the two: 1 on the cells, 0 filtered (`None` when a figure is
    /// missing or the references coincide).
    pub step_share: Option<f64>,
}

/// The staircase comparisons of a view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Edges {
    /// Over edges between classes that all grow seeds.
    pub between_seeded: Staircase,
    /// Over every edge.
    pub all: Staircase,
}

/// What a tree's ground point says of the edges around it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeShares {
    /// The nearest cell grows trees.
    pub nearest: bool,
    /// The four nearest cells' bilinear share of trees' classes.
    pub bilinear: f64,
    /// All four grow seeds.
    pub seeded_around: bool,
    /// Horizontal distance from the camera, metres.
    pub distance_m: f64,
}

/// The shares at the ground point of every tree (seed of a tree species) pass 3 selected in the
/// view `renderer` last settled from `camera`; `None` without seeds.
pub fn tree_shares(renderer: &Renderer, camera: &Camera) -> Result<Option<Vec<TreeShares>>, PhotoError> {
    let (Some(table), Some((records, _))) = (renderer.class_table(), renderer.read_seeds()?) else {
        return Ok(None);
    };
    let manifest = &renderer.dataset.manifest;
    let half_spacing_m = 0.5 * manifest.height.spacing_m;
    let placing = renderer.exact_placing(camera);
    let eye_grid_m = placing.camera_grid_m();
    let mut landcover = Landcover::new(&renderer.dataset, Some(table));
    let mut trees = Vec::new();
    for record in &records {
        let species = SpeciesLod::unpack(record.species_lod).species as usize;
        if table.species.get(species).is_none_or(|s| s.kind != SpeciesKind::Tree) {
            continue;
        }
        let grid_m = placing.grid_m(glam::DVec3::from(record.position_rel_m.map(f64::from)));
        let rel = grid_m - eye_grid_m;
        let p = [grid_m.x, grid_m.y];
        let (bilinear, seeded_around) = landcover.wooded_fraction(p, half_spacing_m)?;
        let nearest = landcover.wooded(p, half_spacing_m)?;
        trees.push(TreeShares { nearest, bilinear, seeded_around, distance_m: rel.x.hypot(rel.y) });
    }
    Ok(Some(trees))
}

/// Compares `trees` with the references integrated over `keys`' pixels.
pub fn edges(keys: &PixelKeys, trees: &[TreeShares]) -> Edges {
    let reach_m = trees.iter().map(|t| t.distance_m).fold(0.0, f64::max);
    let mut sums = [Sums::default(); 2];
    for (i, &fraction) in keys.wooded_fraction.iter().enumerate() {
        let (bilinear, area) = (f64::from(fraction), f64::from(keys.ground_area_m2[i]));
        if !near_edge(bilinear)
            || area <= 0.0
            || area.is_nan()
            || f64::from(keys.ground_distance_m[i]) > reach_m
        {
            continue;
        }
        let nearest = f64::from(u8::from(keys.wooded[i]));
        for (k, s) in sums.iter_mut().enumerate() {
            if k == 1 || keys.seeded_around[i] {
                s.add_area(area, nearest, bilinear);
            }
        }
    }
    for t in trees.iter().filter(|t| near_edge(t.bilinear)) {
        let step = f64::from(u8::from(t.nearest)) - t.bilinear;
        for (k, s) in sums.iter_mut().enumerate() {
            if k == 1 || t.seeded_around {
                s.trees += 1;
                s.trees_step += step;
            }
        }
    }
    Edges { between_seeded: sums[0].staircase(), all: sums[1].staircase() }
}

fn near_edge(bilinear: f64) -> bool {
    bilinear > 1e-6 && bilinear < 1.0 - 1e-6
}

/// Area integrals near edges and the trees' steps.
#[derive(Debug, Default, Clone, Copy)]
struct Sums {
    pixels: usize,
    /// ∫ nearest, ∫ nearest · step, ∫ bilinear, ∫ bilinear · step (m²).
    nearest: f64,
    nearest_step: f64,
    bilinear: f64,
    bilinear_step: f64,
    trees: usize,
    trees_step: f64,
}

impl Sums {
    fn add_area(&mut self, area: f64, nearest: f64, bilinear: f64) {
        let step = nearest - bilinear;
        self.pixels += 1;
        self.nearest += area * nearest;
        self.nearest_step += area * nearest * step;
        self.bilinear += area * bilinear;
        self.bilinear_step += area * bilinear * step;
    }

    fn staircase(&self) -> Staircase {
        let ratio = |num: f64, den: f64| (den > 0.0).then(|| num / den);
        let trees_step = ratio(self.trees_step, self.trees as f64);
        let on_cells_step = ratio(self.nearest_step, self.nearest);
        let filtered_step = ratio(self.bilinear_step, self.bilinear);
        let step_share = match (trees_step, on_cells_step, filtered_step) {
            (Some(t), Some(c), Some(f)) if (c - f).abs() > 1e-9 => Some((t - f) / (c - f)),
            _ => None,
        };
        Staircase {
            pixels: self.pixels,
            trees: self.trees,
            trees_step,
            on_cells_step,
            filtered_step,
            step_share,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of cells 16 pixels wide (a pixel 1 m²), every other pair wooded: its keys, and the
    /// trees `keep(bilinear, nearest)` keeps of candidates four to a pixel, off its centre.
    fn strip(mut keep: impl FnMut(f64, bool) -> bool) -> Edges {
        let w = 256usize;
        let cell_wooded = |c: i64| f64::from(u8::from(c.rem_euclid(4) < 2));
        // Shares at x pixels along (cell centres lie half a cell in).
        let shares = |x: f64| {
            let u = x / 16.0;
            let base = (u - 0.5).floor();
            let f = u - 0.5 - base;
            let bilinear = (1.0 - f) * cell_wooded(base as i64) + f * cell_wooded(base as i64 + 1);
            (cell_wooded(u.floor() as i64) > 0.0, bilinear)
        };
        // Every pixel at the trees' distance (0), so all lie within their reach.
        let mut keys =
            PixelKeys { ground_distance_m: vec![0.0; w], ..PixelKeys::forest([w as u32, 1], vec![0; w]) };
        for x in 0..w {
            let (nearest, bilinear) = shares(x as f64 + 0.5);
            keys.wooded[x] = nearest;
            keys.wooded_fraction[x] = bilinear as f32;
        }
        let trees: Vec<TreeShares> = (0..4 * w)
            .map(|k| shares((k as f64 + 0.37) / 4.0))
            .filter(|&(nearest, bilinear)| keep(bilinear, nearest))
            .map(|(nearest, bilinear)| TreeShares { nearest, bilinear, seeded_around: true, distance_m: 0.0 })
            .collect();
        edges(&keys, &trees)
    }

    #[test]
    fn trees_on_the_cells_are_a_whole_step() {
        let on_cells = strip(|_, nearest| nearest).between_seeded;
        assert!((on_cells.step_share.unwrap() - 1.0).abs() < 0.02, "{on_cells:?}");
        assert!(on_cells.trees > 0 && on_cells.pixels > 0);
        // No trees: no share, not a 0 that would read as a filtered edge.
        assert_eq!(strip(|_, _| false).all.step_share, None);
    }

    #[test]
    fn trees_at_the_bilinear_share_have_no_step() {
        // A tree kept with probability equal to its bilinear share, by a fixed generator.
        let mut state = 0x9e37_79b9_u32;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            f64::from(state) / f64::from(u32::MAX)
        };
        let draws = 400;
        let share: f64 = (0..draws)
            .map(|_| strip(|bilinear, _| next() < bilinear).between_seeded.step_share.unwrap())
            .sum::<f64>()
            / f64::from(draws);
        assert!(share.abs() < 0.05, "mean step share {share}");
    }
}
