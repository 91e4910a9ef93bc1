//! How it works: DEM voids are filled so that every tile that reads a sample gets the same value,
//! whichever window it reads, without ever holding the DEM whole.
//!
//! The fill is *local*. A void sample becomes a coarse surface of the DEM (`CoarseGrid`) plus the
//! inverse-distance-weighted mean of the residuals (height minus that surface) of the valid samples
//! on void boundaries within `FILL_RADIUS` of it. Near a boundary the fill meets its heights;
//! further in it follows the coarse surface, the terrain's trend, instead of flattening into the
//! plateaus of a plain inverse-distance fill. Franke–Little weights fall to zero at the radius, so
//! nothing jumps where a boundary sample leaves the disc. A void sample's value thus depends only
//! on samples within the radius (and on the coarse surface, which is global), and a window padded
//! by the radius computes it exactly as any other window does. Sums run in one canonical order
//! (boundary samples bucketed on a grid fixed in grid space, scan order inside a bucket), so the
//! results agree to the bit.
//!
//! The coarse surface holds the mean of the valid samples of each coarse cell, computed once while
//! the DEM is scanned; empty cells (wide voids, the grid beyond a reprojected DEM's edge) are grown
//! from their neighbours and smoothed. Filled values are clamped to the range of the valid heights:
//! no spikes, no pits.

use terramp::dataset::Window;

/// Voids take their values from valid samples at most this many samples away.
pub const FILL_RADIUS: u32 = 32;
/// What a coarse grid's bytes begin with (`CoarseGrid::to_bytes`).
const COARSE_TAG: &[u8; 8] = b"TRCOARS1";
/// The coarse fallback has at most this many cells per axis (its cells grow with the DEM).
const COARSE_MAX_CELLS: u32 = 512;
/// Relaxation rounds that turn the coarse cells grown into wide voids into a smooth surface.
const COARSE_SMOOTHING_ROUNDS: usize = 64;

/// Indices of the 8 (or 4, without `diagonals`) neighbours of cell `i` in a grid of `cells`.
fn neighbours(cells: [usize; 2], i: usize, diagonals: bool) -> impl Iterator<Item = usize> {
    let (nx, ny) = (cells[0] as i64, cells[1] as i64);
    let (cx, cy) = ((i as i64) % nx, (i as i64) / nx);
    (-1..=1)
        .flat_map(move |dy| (-1..=1).map(move |dx| (dx, dy)))
        .filter(move |&(dx, dy)| (dx, dy) != (0, 0) && (diagonals || dx == 0 || dy == 0))
        .map(move |(dx, dy)| (cx + dx, cy + dy))
        .filter(move |&(x, y)| (0..nx).contains(&x) && (0..ny).contains(&y))
        .map(move |(x, y)| (y * nx + x) as usize)
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, count) = values.fold((0.0, 0u32), |(s, n), v| (s + v, n + 1));
    (count > 0).then(|| sum / f64::from(count))
}

/// Accumulates the coarse summary while the DEM is scanned.
pub struct CoarseBuilder {
    step: u32,
    cells: [usize; 2],
    sum: Vec<f64>,
    count: Vec<u32>,
}

impl CoarseBuilder {
    pub fn new(size: [u32; 2]) -> Self {
        let step = FILL_RADIUS.max(size[0].max(size[1]).div_ceil(COARSE_MAX_CELLS));
        let cells = size.map(|n| n.div_ceil(step) as usize);
        Self { step, cells, sum: vec![0.0; cells[0] * cells[1]], count: vec![0; cells[0] * cells[1]] }
    }

    /// Records the valid sample (`x`, `y`).
    pub fn add(&mut self, x: u32, y: u32, height_m: f32) {
        let cell = (y / self.step) as usize * self.cells[0] + (x / self.step) as usize;
        self.sum[cell] += f64::from(height_m);
        self.count[cell] += 1;
    }

    /// The finished grid, or `None` when no sample at all was valid.
    pub fn finish(self) -> Option<CoarseGrid> {
        let mut known: Vec<bool> = self.count.iter().map(|&n| n > 0).collect();
        if !known.contains(&true) {
            return None;
        }
        let mut heights: Vec<f64> = self
            .sum
            .iter()
            .zip(&self.count)
            .map(|(&s, &n)| if n > 0 { s / f64::from(n) } else { 0.0 })
            .collect();
        let empty: Vec<usize> = (0..known.len()).filter(|&i| !known[i]).collect();
        let neighbours = |i: usize, diagonals: bool| neighbours(self.cells, i, diagonals);
        // Grow known cells into empty ones a ring per round, then smooth what grew, each round
        // from the previous one only (so the result does not depend on the visiting order).
        while known.contains(&false) {
            let grown: Vec<(usize, f64)> = empty
                .iter()
                .filter(|&&i| !known[i])
                .filter_map(|&i| {
                    mean(neighbours(i, true).filter(|&j| known[j]).map(|j| heights[j])).map(|h| (i, h))
                })
                .collect();
            for (i, height) in grown {
                heights[i] = height;
                known[i] = true;
            }
        }
        for _ in 0..COARSE_SMOOTHING_ROUNDS {
            let smoothed: Vec<f64> = empty
                .iter()
                .map(|&i| mean(neighbours(i, false).map(|j| heights[j])).unwrap_or(heights[i]))
                .collect();
            for (&i, height) in empty.iter().zip(smoothed) {
                heights[i] = height;
            }
        }
        Some(CoarseGrid { step: self.step, cells: self.cells, heights })
    }
}

/// A gap-free, coarse version of the DEM: the fallback for the middle of wide voids.
#[derive(Debug, PartialEq)]
pub struct CoarseGrid {
    step: u32,
    cells: [usize; 2],
    heights: Vec<f64>,
}

impl CoarseGrid {
    /// The grid as bytes (a tag, the step, the cells, each height's f64 bits, all little-endian),
    /// for a partitioned build's plan to hand every job the scan's grid exactly.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = COARSE_TAG.to_vec();
        bytes.extend(self.step.to_le_bytes());
        bytes.extend(self.cells.iter().flat_map(|&n| (n as u32).to_le_bytes()));
        bytes.extend(self.heights.iter().flat_map(|h| h.to_le_bytes()));
        bytes
    }

    /// The grid `to_bytes` wrote; `None` for anything else.
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let rest = bytes.strip_prefix(COARSE_TAG)?;
        let word = |i: usize| Some(u32::from_le_bytes(rest.get(4 * i..4 * i + 4)?.try_into().ok()?));
        let (step, cells) = (word(0)?, [word(1)? as usize, word(2)? as usize]);
        let heights: Vec<f64> = rest[12..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
            .collect();
        // At least one cell: `at` reads cell n − 1 of each axis.
        let whole = rest.len() == 12 + 8 * heights.len()
            && !heights.is_empty()
            && heights.len() == cells[0].checked_mul(cells[1])?;
        (whole && step > 0 && heights.iter().all(|h| h.is_finite())).then_some(Self { step, cells, heights })
    }

    /// Bilinear height at sample (`x`, `y`) between coarse cell centres.
    fn at(&self, x: u32, y: u32) -> f64 {
        let step = f64::from(self.step);
        let axis = |v: u32, n: usize| {
            let u = ((f64::from(v) + 0.5) / step - 0.5).clamp(0.0, (n - 1) as f64);
            let i = u.floor() as usize;
            (i, (i + 1).min(n - 1), u - i as f64)
        };
        let ((x0, x1, fx), (y0, y1, fy)) = (axis(x, self.cells[0]), axis(y, self.cells[1]));
        let h = |cx: usize, cy: usize| self.heights[cy * self.cells[0] + cx];
        let south = h(x0, y0) + (h(x1, y0) - h(x0, y0)) * fx;
        let north = h(x0, y1) + (h(x1, y1) - h(x0, y1)) * fx;
        south + (north - south) * fy
    }
}

/// A valid sample next to a void, with its height relative to the coarse surface.
#[derive(Clone, Copy)]
struct Boundary {
    x: u32,
    y: u32,
    residual_m: f64,
}

/// Fills the voids of any window of one DEM.
pub struct VoidFill {
    size: [u32; 2],
    coarse: CoarseGrid,
    /// Range of the valid heights: filled values never leave it.
    range_m: [f32; 2],
}

impl VoidFill {
    pub fn new(size: [u32; 2], coarse: CoarseGrid, range_m: [f32; 2]) -> Self {
        Self { size, coarse, range_m }
    }

    /// The coarse surface the fill falls back on.
    pub fn coarse(&self) -> &CoarseGrid {
        &self.coarse
    }

    /// The window whose samples `fill` needs: `window` grown by the radius (and the one sample
    /// that tells whether a sample is on a boundary), clamped to the grid.
    pub fn padded(&self, window: Window) -> Window {
        let pad = FILL_RADIUS + 1;
        let (x0, y0) = (window.x0.saturating_sub(pad), window.y0.saturating_sub(pad));
        let x1 = (window.x0 + window.width + pad).min(self.size[0]);
        let y1 = (window.y0 + window.height + pad).min(self.size[1]);
        Window { x0, y0, width: x1 - x0, height: y1 - y0 }
    }

    /// The samples of `window` with every void (`NaN`) filled, from `padded_m`, the samples of
    /// `self.padded(window)`.
    pub fn fill(&self, window: Window, padded_m: &[f32]) -> Vec<f32> {
        let p = self.padded(window);
        debug_assert_eq!(padded_m.len(), (p.width * p.height) as usize);
        let at = |x: u32, y: u32| padded_m[((y - p.y0) * p.width + (x - p.x0)) as usize];
        let buckets = Buckets::collect(p, &at, &self.coarse);
        let mut out = Vec::with_capacity((window.width * window.height) as usize);
        for y in window.y0..window.y0 + window.height {
            for x in window.x0..window.x0 + window.width {
                let height_m = at(x, y);
                out.push(if height_m.is_nan() { self.filled(&buckets, x, y) } else { height_m });
            }
        }
        out
    }

    fn filled(&self, buckets: &Buckets, x: u32, y: u32) -> f32 {
        let radius = f64::from(FILL_RADIUS);
        // Residuals fade to the coarse surface: its weight is a boundary sample's at three
        // quarters of the radius, so it decides only where no boundary is near.
        let (mut weighted_m, mut weights) = (0.0, (3.0 * radius).powi(2).recip());
        for sample in buckets.near(x, y) {
            let (dx, dy) = (f64::from(sample.x) - f64::from(x), f64::from(sample.y) - f64::from(y));
            let distance_sq = dx * dx + dy * dy;
            if distance_sq < radius * radius {
                let distance = distance_sq.sqrt();
                let weight = ((radius - distance) / (radius * distance)).powi(2);
                weighted_m += weight * sample.residual_m;
                weights += weight;
            }
        }
        let height_m = self.coarse.at(x, y) + weighted_m / weights;
        (height_m as f32).clamp(self.range_m[0], self.range_m[1])
    }
}

/// Boundary samples of a padded window, bucketed by `FILL_RADIUS`-sized cells of grid space.
struct Buckets {
    /// Bucket coordinates of the first bucket, and buckets per axis.
    first: [u32; 2],
    count: [u32; 2],
    samples: Vec<Vec<Boundary>>,
}

impl Buckets {
    fn collect(p: Window, at: &impl Fn(u32, u32) -> f32, coarse: &CoarseGrid) -> Self {
        let first = [p.x0 / FILL_RADIUS, p.y0 / FILL_RADIUS];
        let last = [(p.x0 + p.width - 1) / FILL_RADIUS, (p.y0 + p.height - 1) / FILL_RADIUS];
        let count = [last[0] - first[0] + 1, last[1] - first[1] + 1];
        let mut samples = vec![Vec::new(); (count[0] * count[1]) as usize];
        // Outside the padded window counts as valid: such samples are beyond the radius anyway.
        let void = |x: u32, y: u32| {
            (p.x0..p.x0 + p.width).contains(&x) && (p.y0..p.y0 + p.height).contains(&y) && at(x, y).is_nan()
        };
        for y in p.y0..p.y0 + p.height {
            for x in p.x0..p.x0 + p.width {
                let height_m = at(x, y);
                let on_boundary = !height_m.is_nan()
                    && ((x > 0 && void(x - 1, y))
                        || void(x + 1, y)
                        || (y > 0 && void(x, y - 1))
                        || void(x, y + 1));
                if on_boundary {
                    let bucket = (y / FILL_RADIUS - first[1]) * count[0] + (x / FILL_RADIUS - first[0]);
                    let residual_m = f64::from(height_m) - coarse.at(x, y);
                    samples[bucket as usize].push(Boundary { x, y, residual_m });
                }
            }
        }
        Self { first, count, samples }
    }

    /// Boundary samples of the 3 × 3 buckets around (`x`, `y`), in canonical order.
    fn near(&self, x: u32, y: u32) -> impl Iterator<Item = &Boundary> {
        let span = |v: u32, axis: usize| {
            let b = v / FILL_RADIUS;
            let lo = b.saturating_sub(1).max(self.first[axis]);
            let hi = (b + 1).min(self.first[axis] + self.count[axis] - 1);
            lo..=hi
        };
        let (xs, ys) = (span(x, 0), span(y, 1));
        ys.flat_map(move |by| xs.clone().map(move |bx| (bx, by))).flat_map(move |(bx, by)| {
            let index = (by - self.first[1]) * self.count[0] + (bx - self.first[0]);
            self.samples[index as usize].iter()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: [u32; 2] = [300, 200];

    /// A sloping field with a one-sample void, a small void, a void wider than the fill disc and
    /// the whole west edge void.
    fn field() -> Vec<f32> {
        let mut heights: Vec<f32> =
            (0..SIZE[1]).flat_map(|y| (0..SIZE[0]).map(move |x| 100.0 + x as f32 + 0.5 * y as f32)).collect();
        let mut punch = |x0: u32, y0: u32, w: u32, h: u32| {
            for y in y0..y0 + h {
                for x in x0..x0 + w {
                    heights[(y * SIZE[0] + x) as usize] = f32::NAN;
                }
            }
        };
        punch(50, 50, 1, 1);
        punch(120, 30, 7, 5);
        punch(150, 80, 100, 90);
        punch(0, 0, 3, SIZE[1]);
        heights
    }

    fn filler(heights: &[f32]) -> VoidFill {
        let mut coarse = CoarseBuilder::new(SIZE);
        let mut range = [f32::MAX, f32::MIN];
        for (i, &h) in heights.iter().enumerate() {
            if !h.is_nan() {
                coarse.add(i as u32 % SIZE[0], i as u32 / SIZE[0], h);
                range = [range[0].min(h), range[1].max(h)];
            }
        }
        VoidFill::new(SIZE, coarse.finish().unwrap(), range)
    }

    fn fill_window(fill: &VoidFill, heights: &[f32], window: Window) -> Vec<f32> {
        let p = fill.padded(window);
        let padded: Vec<f32> = (p.y0..p.y0 + p.height)
            .flat_map(|y| (p.x0..p.x0 + p.width).map(move |x| heights[(y * SIZE[0] + x) as usize]))
            .collect();
        fill.fill(window, &padded)
    }

    #[test]
    fn every_void_is_filled_within_the_valid_range() {
        let heights = field();
        let fill = filler(&heights);
        let whole = Window { x0: 0, y0: 0, width: SIZE[0], height: SIZE[1] };
        let filled = fill_window(&fill, &heights, whole);
        let (lo, hi) = (fill.range_m[0], fill.range_m[1]);
        assert!(filled.iter().all(|h| (lo..=hi).contains(h)), "a filled value left [{lo}, {hi}]");
        for (a, b) in heights.iter().zip(&filled) {
            assert!(a.is_nan() || a == b, "a valid sample changed");
        }
        // A one-sample void in a plane is very nearly the plane.
        let at = |x: u32, y: u32| filled[(y * SIZE[0] + x) as usize];
        assert!((at(50, 50) - (100.0 + 50.0 + 25.0)).abs() < 1.0, "{}", at(50, 50));
    }

    #[test]
    fn any_window_gives_the_same_values_to_the_bit() {
        let heights = field();
        let fill = filler(&heights);
        let whole = fill_window(&fill, &heights, Window { x0: 0, y0: 0, width: SIZE[0], height: SIZE[1] });
        for window in [
            Window { x0: 140, y0: 70, width: 37, height: 41 },
            Window { x0: 0, y0: 0, width: 9, height: 200 },
            Window { x0: 199, y0: 120, width: 101, height: 80 },
            Window { x0: 118, y0: 29, width: 3, height: 3 },
        ] {
            let part = fill_window(&fill, &heights, window);
            for (k, &h) in part.iter().enumerate() {
                let (x, y) = (window.x0 + k as u32 % window.width, window.y0 + k as u32 / window.width);
                assert_eq!(
                    h.to_bits(),
                    whole[(y * SIZE[0] + x) as usize].to_bits(),
                    "({x}, {y}) in {window:?}"
                );
            }
        }
    }

    #[test]
    fn wide_voids_fall_back_to_the_coarse_grid_smoothly() {
        let heights = field();
        let fill = filler(&heights);
        let filled = fill_window(&fill, &heights, Window { x0: 0, y0: 0, width: SIZE[0], height: SIZE[1] });
        let at = |x: u32, y: u32| filled[(y * SIZE[0] + x) as usize];
        // Across the wide void, neighbouring samples differ by little more than the slope of the
        // field (1 m per sample east-west): it follows the terrain's trend, without plateaus.
        for x in 149..250 {
            let step = at(x + 1, 125) - at(x, 125);
            assert!((-1.0..2.0).contains(&step), "step of {step} m at x = {x}");
        }
    }

    #[test]
    fn the_coarse_grid_survives_its_bytes_and_refuses_others() {
        let fill = filler(&field());
        let bytes = fill.coarse().to_bytes();
        assert_eq!(CoarseGrid::from_bytes(&bytes).as_ref(), Some(fill.coarse()));
        assert_eq!(CoarseGrid::from_bytes(&bytes[..bytes.len() - 1]), None, "a truncated grid");
        assert_eq!(CoarseGrid::from_bytes(&bytes[..10]), None, "a header cut short");
        assert_eq!(CoarseGrid::from_bytes(b"something else entirely"), None);
        // No cells (and so no heights): `at` would take cell 0 − 1 (found by the overflow audit,
        // issue 42).
        let empty: Vec<u8> = [COARSE_TAG.as_slice(), &1u32.to_le_bytes(), &[0; 8]].concat();
        assert_eq!(CoarseGrid::from_bytes(&empty), None, "a grid of no cells");
    }
}
