//! How it works: the generic seed patterns of pass 3 (paper § 4.4, DESIGN "Seed selection"). Each
//! of the P patterns is a set of 2D positions in the unit square [0, 1)², laid over one ring-0 TLM
//! cell; a cell shows pattern `hash(cell) mod P`. Two steps make a pattern:
//!
//! 1. **Poisson-disk candidates** by Bridson's algorithm (SIGGRAPH sketch 2007) on the *torus*:
//!    distances wrap around the square's edges, so a pattern tiles against itself and against its
//!    neighbour cells' copies without seams. A background grid of cells no wider than r/√2 holds at
//!    most one point each, so a candidate is tested against the 5 × 5 cells around it (nearest
//!    first: most candidates fail there). Bridson with 30 attempts fills the torus at N r² ≈ 0.6
//!    (a maximal Poisson-disk set at ≈ 0.68), so the radius r = √(0.55 / N) gives about 1.09 N
//!    points for N wanted; should a run fall short, r shrinks by 5 % and it runs again.
//! 2. **Ranking by greedy farthest-point ordering** (toroidal): the first seed is Bridson's first
//!    point, and each next one is the remaining candidate farthest from all chosen so far. Every
//!    prefix is then well spread, which is what thinning needs: a class of density ρ keeps the
//!    seeds of rank < ρ × cell area, and those form blue noise at any ρ. Greedy farthest-point is
//!    the classical k-center 2-approximation: the first k seeds are separated by at least
//!    d_k (the distance at which seed k was chosen), and every candidate lies within d_{k+1} of
//!    them, so the prefix is both a packing and a covering. Only the best-ranked N candidates
//!    are kept; the dropped ones are those closest to their neighbours, which evens the pattern
//!    out. It runs in O(M log M): each candidate keeps its squared distance to the chosen set;
//!    after choosing a seed at distance d, only candidates within d of it can get closer, and the
//!    grid finds them; a max-heap with lazy deletion yields the next farthest.
//!    (Progressive Bridson with shrinking radii was the alternative: within one radius the disk
//!    front grows from the first point, so a prefix ending mid-radius is lopsided.)
//!    Measured over 16 patterns of 1024 to 4096 seeds, every prefix of k seeds has its closest
//!    pair at least 0.66 / √k apart (0.75 / √N for the whole pattern; a hexagonal packing: 1.07)
//!    and leaves no point of the square farther than 1.15 / √k from a seed.
//!
//! Everything is deterministic: a SplitMix64 stream per (seed, pattern), annulus samples by
//! rejection from a square (no trigonometry, whose last bits vary between math libraries), and
//! only IEEE-exact operations (+, −, ×, √, floor, rounding casts) on positions already rounded to
//! the f32 they are stored as. The same seed gives bit-identical patterns on every run and
//! platform; patterns are generated in parallel, each from its own stream.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use rayon::prelude::*;

/// Bridson's attempts around an active point before it retires (his k).
const ATTEMPTS: u32 = 30;
/// N r² for the first Bridson radius: a bit under the ≈ 0.6 Bridson reaches, so about 1.09 N points.
const FILL: f64 = 0.55;
/// How much the radius shrinks when a run yields fewer than N points.
const SHRINK: f64 = 0.95;

/// P generic patterns of blue-noise seed positions, each sorted by rank (index = rank).
#[derive(Debug, Clone, PartialEq)]
pub struct SeedPatterns {
    /// How many patterns there are, P (`tlm.patterns`, 1 to 255).
    pub count: u32,
    /// Seeds in each pattern (`seeds.seeds_per_pattern`); all P patterns hold the same number.
    pub seeds_per_pattern: u32,
    /// pattern p's seed of rank r at p * seeds_per_pattern + r, unit square
    pub positions_unit: Vec<[f32; 2]>,
}

impl SeedPatterns {
    /// `count` patterns of `seeds_per_pattern` seeds each, from the germ `seed`.
    pub fn generate(count: u32, seeds_per_pattern: u32, seed: u32) -> Self {
        let n = seeds_per_pattern as usize;
        let positions_unit = (0..count)
            .into_par_iter()
            .map(|p| one_pattern(n, (u64::from(seed) << 32) | u64::from(p)))
            .collect::<Vec<_>>()
            .concat();
        Self { count, seeds_per_pattern, positions_unit }
    }

    /// Pattern `p`'s seeds in rank order (empty for p ≥ count).
    pub fn pattern(&self, p: u32) -> &[[f32; 2]] {
        let n = self.seeds_per_pattern as usize;
        let start = p as usize * n;
        self.positions_unit.get(start..start + n).unwrap_or(&[])
    }
}

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, fast, and the same on every platform.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1), 53 bits.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in 0..n (n ≥ 1), by multiply-shift.
    fn below(&mut self, n: usize) -> usize {
        ((u128::from(self.next_u64()) * n as u128) >> 64) as usize
    }
}

/// A coordinate wrapped into [0, 1) and rounded to the f32 it will be stored as.
fn wrap_unit(x: f64) -> f64 {
    let w = (x - x.floor()) as f32;
    if w >= 1.0 { 0.0 } else { f64::from(w) }
}

/// Squared toroidal distance between two points of the unit square.
fn torus_d2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let dx = (a[0] - b[0]).abs();
    let dy = (a[1] - b[1]).abs();
    let (dx, dy) = (dx.min(1.0 - dx), dy.min(1.0 - dy));
    dx * dx + dy * dy
}

/// A toroidal background grid holding at most one point per cell.
struct Grid {
    side: usize,
    cells: Vec<u32>,
}

impl Grid {
    const EMPTY: u32 = u32::MAX;

    /// Cells no wider than `max_cell`.
    fn new(max_cell: f64) -> Self {
        let side = ((1.0 / max_cell).ceil() as usize).max(1);
        Self { side, cells: vec![Self::EMPTY; side * side] }
    }

    fn cell_of(&self, p: [f64; 2]) -> (usize, usize) {
        let side = self.side as f64;
        let c = |v: f64| ((v * side) as usize).min(self.side - 1);
        (c(p[0]), c(p[1]))
    }

    /// The cells of an axis within `reach` of `c`, each once, wrapping around.
    fn axis(&self, c: usize, reach: usize) -> std::ops::Range<usize> {
        if 2 * reach + 1 >= self.side {
            0..self.side
        } else {
            c + self.side - reach..c + self.side + reach + 1
        }
    }

    /// Calls `f` with every point stored within `reach` cells of `p`'s cell.
    fn for_near(&self, p: [f64; 2], reach: usize, mut f: impl FnMut(u32)) {
        let (cx, cy) = self.cell_of(p);
        for y in self.axis(cy, reach) {
            let row = (y % self.side) * self.side;
            for x in self.axis(cx, reach) {
                let i = self.cells[row + x % self.side];
                if i != Self::EMPTY {
                    f(i);
                }
            }
        }
    }

    /// Whether `hit` holds for a point stored within 2 cells of `p`'s cell, nearest cells first
    /// (Bridson's test, its hot loop: most candidates fail on a near cell).
    fn any_within_2(&self, p: [f64; 2], mut hit: impl FnMut(u32) -> bool) -> bool {
        if self.side < 5 {
            let mut any = false;
            self.for_near(p, 2, |i| any = any || hit(i));
            return any;
        }
        let (cx, cy) = self.cell_of(p);
        let side = self.side as isize;
        let wrap = |c: usize, d: i8| {
            let v = c as isize + isize::from(d);
            (if v < 0 {
                v + side
            } else if v >= side {
                v - side
            } else {
                v
            }) as usize
        };
        NEAR_5X5.iter().any(|&(dx, dy)| {
            let i = self.cells[wrap(cy, dy) * self.side + wrap(cx, dx)];
            i != Self::EMPTY && hit(i)
        })
    }
}

/// The 5 × 5 cell offsets, nearest first.
const NEAR_5X5: [(i8, i8); 25] = [
    (0, 0),
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (-1, 1),
    (1, -1),
    (-1, -1),
    (2, 0),
    (-2, 0),
    (0, 2),
    (0, -2),
    (2, 1),
    (2, -1),
    (-2, 1),
    (-2, -1),
    (1, 2),
    (-1, 2),
    (1, -2),
    (-1, -2),
    (2, 2),
    (-2, 2),
    (2, -2),
    (-2, -2),
];

/// One pattern of `n` ranked seeds from stream `stream`.
fn one_pattern(n: usize, stream: u64) -> Vec<[f32; 2]> {
    if n == 0 {
        return Vec::new();
    }
    let mut rng = SplitMix64(stream.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x5eed_5eed_5eed_5eed);
    let mut radius = (FILL / n as f64).sqrt();
    loop {
        let (points, grid) = bridson(radius, &mut rng);
        if points.len() >= n {
            let order = farthest_point_order(&points, &grid, n);
            return order.iter().map(|&i| points[i as usize].map(|v| v as f32)).collect();
        }
        radius *= SHRINK;
    }
}

/// Bridson's Poisson-disk sampling of the unit torus at `radius`: the points and their grid.
fn bridson(radius: f64, rng: &mut SplitMix64) -> (Vec<[f64; 2]>, Grid) {
    let r2 = radius * radius;
    // A hair under r/√2, so that two points of one cell are always closer than r, rounding aside.
    let mut grid = Grid::new(0.999 * radius / std::f64::consts::SQRT_2);
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut active: Vec<u32> = Vec::new();
    let first = [wrap_unit(rng.unit()), wrap_unit(rng.unit())];
    insert(first, &mut points, &mut grid, &mut active);
    while !active.is_empty() {
        let slot = rng.below(active.len());
        let centre = points[active[slot] as usize];
        let mut found = false;
        for _ in 0..ATTEMPTS {
            // A point of the annulus [r, 2r) around the centre, by rejection from its square.
            let (dx, dy) = ((rng.unit() * 4.0 - 2.0) * radius, (rng.unit() * 4.0 - 2.0) * radius);
            let d2 = dx * dx + dy * dy;
            if d2 < r2 || d2 >= 4.0 * r2 {
                continue;
            }
            let candidate = [wrap_unit(centre[0] + dx), wrap_unit(centre[1] + dy)];
            // Cells are at most r/√2 wide, so every point within r lies within 2 cells.
            if !grid.any_within_2(candidate, |i| torus_d2(points[i as usize], candidate) < r2) {
                insert(candidate, &mut points, &mut grid, &mut active);
                found = true;
                break;
            }
        }
        if !found {
            active.swap_remove(slot);
        }
    }
    (points, grid)
}

fn insert(p: [f64; 2], points: &mut Vec<[f64; 2]>, grid: &mut Grid, active: &mut Vec<u32>) {
    let (cx, cy) = grid.cell_of(p);
    grid.cells[cy * grid.side + cx] = points.len() as u32;
    active.push(points.len() as u32);
    points.push(p);
}

/// The indices of the `keep` best-ranked `points` by greedy farthest-point ordering on the torus,
/// starting from point 0. `grid` holds every point (one per cell).
fn farthest_point_order(points: &[[f64; 2]], grid: &Grid, keep: usize) -> Vec<u32> {
    let cell = 1.0 / grid.side as f64;
    // Squared distance of each point to the chosen set; chosen points hold -1 (no heap entry matches).
    let mut d2 = vec![f64::INFINITY; points.len()];
    // Max-heap of (squared distance bits, smallest index first); stale entries are skipped.
    // Non-negative f64 order like their bit patterns, so ties break on the index, deterministically.
    let mut heap: BinaryHeap<(u64, Reverse<u32>)> = BinaryHeap::new();
    let mut order = Vec::with_capacity(keep);
    let mut next = Some((f64::INFINITY, 0u32));
    while let Some((reach2, chosen)) = next {
        order.push(chosen);
        let c = points[chosen as usize];
        d2[chosen as usize] = -1.0;
        if order.len() == keep {
            break;
        }
        // Only points closer to `chosen` than their current distance change, and every current
        // distance is at most `reach2` (chosen was the farthest): search that far, no farther.
        let reach = if reach2 >= 0.5 { grid.side } else { (reach2.sqrt() / cell).ceil() as usize + 1 };
        grid.for_near(c, reach, |i| {
            let d = torus_d2(points[i as usize], c);
            if d < d2[i as usize] {
                d2[i as usize] = d;
                heap.push((d.to_bits(), Reverse(i)));
            }
        });
        next = None;
        while let Some((bits, Reverse(i))) = heap.pop() {
            if d2[i as usize].to_bits() == bits {
                next = Some((f64::from_bits(bits), i));
                break;
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    fn d2_of(a: [f32; 2], b: [f32; 2]) -> f64 {
        torus_d2(a.map(f64::from), b.map(f64::from))
    }

    /// Smallest toroidal distance between two seeds of `seeds` (brute force).
    fn min_distance(seeds: &[[f32; 2]]) -> f64 {
        let mut best = f64::INFINITY;
        for (i, &a) in seeds.iter().enumerate() {
            for &b in &seeds[i + 1..] {
                best = best.min(d2_of(a, b));
            }
        }
        best.sqrt()
    }

    /// Largest distance from a point of a 64 × 64 probe grid to its nearest seed (brute force).
    fn coverage(seeds: &[[f32; 2]]) -> f64 {
        let mut worst: f64 = 0.0;
        for j in 0..64 {
            for i in 0..64 {
                let probe = [(i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 64.0];
                let near = seeds.iter().map(|&s| d2_of(s, probe)).fold(f64::INFINITY, f64::min);
                worst = worst.max(near);
            }
        }
        worst.sqrt()
    }

    #[test]
    fn patterns_are_deterministic_and_sized() {
        let a = SeedPatterns::generate(4, 256, 7);
        assert_eq!(a, SeedPatterns::generate(4, 256, 7));
        assert_ne!(a.positions_unit, SeedPatterns::generate(4, 256, 8).positions_unit);
        assert_eq!(a.positions_unit.len(), 4 * 256);
        assert_eq!((a.count, a.seeds_per_pattern), (4, 256));
        assert!(a.positions_unit.iter().flatten().all(|&v| (0.0..1.0).contains(&v)));
        for p in 0..4 {
            assert_eq!(a.pattern(p).len(), 256);
            for q in 0..p {
                assert_ne!(a.pattern(p), a.pattern(q), "patterns {p} and {q}");
            }
        }
        assert!(a.pattern(4).is_empty());
        assert!(SeedPatterns::generate(0, 256, 1).positions_unit.is_empty());
        assert_eq!(SeedPatterns::generate(2, 1, 1).positions_unit.len(), 2);
        assert_eq!(SeedPatterns::generate(1, 3, 1).positions_unit.len(), 3);
    }

    #[test]
    fn every_prefix_is_blue_noise() {
        let n = 1024;
        let patterns = SeedPatterns::generate(3, n, 1);
        for p in 0..3 {
            let pattern = patterns.pattern(p);
            for k in [n / 64, n / 16, n / 4, n] {
                let prefix = &pattern[..k as usize];
                let scale = f64::from(k).sqrt();
                let (separation, cover) = (min_distance(prefix) * scale, coverage(prefix) * scale);
                assert!(separation >= 0.65, "pattern {p}, k = {k}: min distance {separation:.3} / sqrt(k)");
                assert!(cover <= 1.2, "pattern {p}, k = {k}: coverage {cover:.3} / sqrt(k)");
            }
        }
    }

    #[test]
    fn a_pattern_tiles_against_itself() {
        // Toroidal distance is what the separation test measures; check it across the seams too.
        let pattern = SeedPatterns::generate(1, 512, 3).pattern(0).to_vec();
        let min_plain = (0.65 / 512f64.sqrt()) as f32;
        let tiled: Vec<[f32; 2]> = (0..4)
            .flat_map(|t| pattern.iter().map(move |s| [s[0] + (t % 2) as f32, s[1] + (t / 2) as f32]))
            .collect();
        for (i, a) in tiled.iter().enumerate() {
            for b in &tiled[i + 1..] {
                assert!((a[0] - b[0]).hypot(a[1] - b[1]) >= min_plain * 0.999);
            }
        }
    }

    #[test]
    fn the_accurate_presets_patterns_are_generated_whole() {
        // How long it takes is `benches/patterns.rs`'s to say, not a test's.
        let patterns = SeedPatterns::generate(16, 4096, 1);
        assert_eq!(patterns.positions_unit.len(), 16 * 4096);
    }
}
