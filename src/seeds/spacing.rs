//! How it works: how seeds are spaced across the borders of the ring-0 cells, measured on any set
//! of seeds in world (or unit) xy, each with the cell it belongs to: the GPU's selected seeds of a
//! real view, or patterns laid side by side. For every seed, its nearest neighbour (a bucket grid,
//! searched ring by ring until no nearer bucket remains) either lies in another cell (`across`) or
//! in the same one; of the latter, those whose segment crosses one of the cell's midlines
//! (`midline`: a border in the same place that no pattern knows about) are a control, since a
//! long segment is likelier to cross a line: under a seamless process the across and midline
//! figures agree.
//!
//! The radial distribution function compares all pairs with pairs across a border. Distances are
//! in units of each centre's local spacing (1 / √λ, λ from its 40 nearest neighbours, so dense
//! forest and sparse shrubland compare), and a pair across a border counts 1 / φ(d), φ being
//! the chance that a segment of length d, placed and turned at random, crosses a square grid of
//! side L (Buffon on a grid: (4dL − d²) / (πL²)). Under a seamless process both curves agree;
//! independent patterns on either side of a border put too many close pairs across it.

use std::collections::HashMap;

/// Bins of the radial distribution function: 0 to 3 local spacings.
pub const RDF_BINS: usize = 30;
/// Width of one bin, in local spacings.
pub const RDF_BIN: f64 = 0.1;
/// Neighbours that estimate a centre's local density: the farthest of them sits at
/// √(k / π) ≈ 3.6 spacings, beyond the curves (whatever bin it fell in would show a spike).
const DENSITY_NEIGHBOURS: usize = 40;

/// Nearest-neighbour distances and the radial distribution function of a seed set, split by
/// whether they cross a cell border.
#[derive(Debug, Clone, Default)]
pub struct BorderSpacing {
    /// Seeds measured (those with at least one neighbour).
    pub seeds: usize,
    /// Nearest-neighbour distances of the seeds whose neighbour lies in another cell.
    pub across: Vec<f64>,
    /// Those whose neighbour lies in the same cell.
    pub inside: Vec<f64>,
    /// Of `inside`, those whose segment crosses a midline of the cell (the control).
    pub midline: Vec<f64>,
    /// g(r) over all pairs, r in local spacings, bin k covering [k, k + 1) × `RDF_BIN`.
    pub rdf_all: [f64; RDF_BINS],
    /// g(r) over pairs across a border, each weighted by 1 / φ(d).
    pub rdf_across: [f64; RDF_BINS],
    /// Centres the radial distribution functions average over.
    pub rdf_centres: usize,
}

/// The `q` quantile (0 to 1) of `values` by the nearest-rank rule; NaN for none.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

impl BorderSpacing {
    /// 1st percentile of the across-border nearest-neighbour distances over the inside ones.
    pub fn ratio(&self) -> f64 {
        quantile(&self.across, 0.01) / quantile(&self.inside, 0.01)
    }

    /// The same ratio for the midline control.
    pub fn midline_ratio(&self) -> f64 {
        quantile(&self.midline, 0.01) / quantile(&self.inside, 0.01)
    }

    /// Pools `other` into this (views of one preset): distances joined, curves averaged by centres.
    pub fn merge(&mut self, other: &Self) {
        let (a, b) = (self.rdf_centres as f64, other.rdf_centres as f64);
        let total = (a + b).max(1.0);
        for k in 0..RDF_BINS {
            self.rdf_all[k] = (self.rdf_all[k] * a + other.rdf_all[k] * b) / total;
            self.rdf_across[k] = (self.rdf_across[k] * a + other.rdf_across[k] * b) / total;
        }
        self.rdf_centres += other.rdf_centres;
        self.seeds += other.seeds;
        self.across.extend_from_slice(&other.across);
        self.inside.extend_from_slice(&other.inside);
        self.midline.extend_from_slice(&other.midline);
    }

    /// Measures `xy` (seed positions), each in cell `cells[i]` of side `cell` (same unit), cell
    /// (i, j) covering [i, i + 1) × [j, j + 1) cells.
    pub fn of(xy: &[[f64; 2]], cells: &[[i64; 2]], cell: f64) -> Self {
        assert_eq!(xy.len(), cells.len(), "one cell per seed");
        let mut out = Self::default();
        if xy.len() < 2 {
            return out;
        }
        let index = Buckets::new(xy);
        let mut weights_all = [0.0; RDF_BINS];
        let mut weights_across = [0.0; RDF_BINS];
        let mut centres = 0usize;
        for (i, &p) in xy.iter().enumerate() {
            let near = index.nearest(xy, p, i, DENSITY_NEIGHBOURS);
            let Some(&(d2, j)) = near.first() else { continue };
            let d = d2.sqrt();
            out.seeds += 1;
            if cells[j] != cells[i] {
                out.across.push(d);
            } else {
                out.inside.push(d);
                let mid = |a: usize| (cells[i][a] as f64 + 0.5) * cell;
                if (0..2).any(|a| (p[a] - mid(a)) * (xy[j][a] - mid(a)) < 0.0) {
                    out.midline.push(d);
                }
            }
            if near.len() < DENSITY_NEIGHBOURS {
                continue;
            }
            // λ = k / (π d_k²): the local spacing 1 / √λ is d_k √(π / k).
            let spacing = near[DENSITY_NEIGHBOURS - 1].0.sqrt()
                * (std::f64::consts::PI / DENSITY_NEIGHBOURS as f64).sqrt();
            let reach = spacing * RDF_BIN * RDF_BINS as f64;
            centres += 1;
            index.for_within(xy, p, reach, |j, d2| {
                if j == i {
                    return;
                }
                let d = d2.sqrt();
                let bin = (d / spacing / RDF_BIN) as usize;
                if bin >= RDF_BINS {
                    return;
                }
                weights_all[bin] += 1.0;
                if cells[j] != cells[i] {
                    weights_across[bin] += 1.0 / crossing_chance(d, cell);
                }
            });
        }
        for (bin, (all, across)) in weights_all.iter().zip(&weights_across).enumerate() {
            // A Poisson process of unit density puts π ((k+1)² − k²) δ² neighbours in bin k.
            let expected = std::f64::consts::PI * ((bin + 1).pow(2) - bin.pow(2)) as f64 * RDF_BIN * RDF_BIN;
            out.rdf_all[bin] = all / (expected * centres.max(1) as f64);
            out.rdf_across[bin] = across / (expected * centres.max(1) as f64);
        }
        out.rdf_centres = centres;
        out
    }
}

/// The chance that a segment of length `d`, placed and turned uniformly at random, crosses a
/// line of a square grid of side `cell` (d < cell).
pub fn crossing_chance(d: f64, cell: f64) -> f64 {
    let d = d.min(cell);
    (4.0 * d * cell - d * d) / (std::f64::consts::PI * cell * cell)
}

/// Seeds bucketed on a square grid about two mean spacings wide.
struct Buckets {
    size: f64,
    cells: HashMap<[i64; 2], Vec<u32>>,
}

impl Buckets {
    fn new(xy: &[[f64; 2]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in xy {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(1e-12);
        let size = 2.0 * (area / xy.len() as f64).sqrt();
        let mut cells: HashMap<[i64; 2], Vec<u32>> = HashMap::new();
        for (i, p) in xy.iter().enumerate() {
            cells.entry(Self::key(size, *p)).or_default().push(i as u32);
        }
        Self { size, cells }
    }

    fn key(size: f64, p: [f64; 2]) -> [i64; 2] {
        [(p[0] / size).floor() as i64, (p[1] / size).floor() as i64]
    }

    /// Visits the buckets of the square ring `ring` around `centre`'s bucket.
    fn ring(&self, centre: [i64; 2], ring: i64, mut f: impl FnMut(&[u32])) {
        for y in -ring..=ring {
            let step = if y.abs() == ring { 1 } else { (2 * ring).max(1) };
            let mut x = -ring;
            while x <= ring {
                if let Some(list) = self.cells.get(&[centre[0] + x, centre[1] + y]) {
                    f(list);
                }
                x += step;
            }
        }
    }

    /// The `k` nearest other seeds of `p` (seed `me`): (squared distance, index), nearest first.
    fn nearest(&self, xy: &[[f64; 2]], p: [f64; 2], me: usize, k: usize) -> Vec<(f64, usize)> {
        let centre = Self::key(self.size, p);
        let mut best: Vec<(f64, usize)> = Vec::new();
        let max_ring = 1 + (self.cells.len() as f64).sqrt() as i64 * 4;
        for ring in 0..=max_ring {
            // Every seed of ring `ring` or beyond is at least (ring − 1) buckets away.
            let floor = (ring - 1).max(0) as f64 * self.size;
            if best.len() == k && best[k - 1].0 <= floor * floor {
                break;
            }
            self.ring(centre, ring, |list| {
                for &j in list {
                    let j = j as usize;
                    if j != me {
                        let d2 = (xy[j][0] - p[0]).powi(2) + (xy[j][1] - p[1]).powi(2);
                        best.push((d2, j));
                    }
                }
            });
            best.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            best.truncate(k);
        }
        best
    }

    /// Calls `f(index, squared distance)` for every seed within `reach` of `p`.
    fn for_within(&self, xy: &[[f64; 2]], p: [f64; 2], reach: f64, mut f: impl FnMut(usize, f64)) {
        let (lo, hi) = (
            Self::key(self.size, [p[0] - reach, p[1] - reach]),
            Self::key(self.size, [p[0] + reach, p[1] + reach]),
        );
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                for &j in self.cells.get(&[x, y]).map_or(&[][..], Vec::as_slice) {
                    let j = j as usize;
                    let d2 = (xy[j][0] - p[0]).powi(2) + (xy[j][1] - p[1]).powi(2);
                    if d2 < reach * reach {
                        f(j, d2);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_take_the_nearest_rank() {
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.0), 1.0);
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), 2.0);
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 1.0), 3.0);
        assert!(quantile(&[], 0.5).is_nan());
    }

    #[test]
    fn a_square_lattice_is_measured_exactly() {
        // A lattice of spacing 0.25 over 4 × 4 cells of side 1: every seed's neighbour is 0.25
        // away; ties go to the lowest index, which lies left or below.
        let xy: Vec<[f64; 2]> =
            (0..256).map(|k| [(k % 16) as f64 * 0.25 + 0.125, (k / 16) as f64 * 0.25 + 0.125]).collect();
        let cells: Vec<[i64; 2]> = xy.iter().map(|p| [p[0].floor() as i64, p[1].floor() as i64]).collect();
        let s = BorderSpacing::of(&xy, &cells, 1.0);
        assert_eq!(s.seeds, 256);
        assert!(s.across.iter().chain(&s.inside).all(|&d| (d - 0.25).abs() < 1e-12));
        assert!(!s.across.is_empty() && !s.midline.is_empty());
        assert_eq!(s.ratio(), 1.0);
    }

    #[test]
    fn a_close_pair_across_a_border_shows() {
        let mut xy: Vec<[f64; 2]> =
            (0..256).map(|k| [(k % 16) as f64 * 0.25 + 0.125, (k / 16) as f64 * 0.25 + 0.125]).collect();
        // Two seeds nudged towards each other across the border x = 2.
        xy[7][0] = 1.99;
        xy[8][0] = 2.01;
        let cells: Vec<[i64; 2]> = xy.iter().map(|p| [p[0].floor() as i64, p[1].floor() as i64]).collect();
        let s = BorderSpacing::of(&xy, &cells, 1.0);
        assert!((quantile(&s.across, 0.0) - 0.02).abs() < 1e-9);
        assert!(s.ratio() < 0.1);
    }

    #[test]
    fn buffon_on_a_grid() {
        assert_eq!(crossing_chance(0.0, 1.0), 0.0);
        // A unit needle always crosses a line of a unit grid? Not quite: (4 − 1) / π.
        assert!((crossing_chance(1.0, 1.0) - 3.0 / std::f64::consts::PI).abs() < 1e-12);
    }
}
