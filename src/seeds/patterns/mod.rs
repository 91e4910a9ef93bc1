//! How it works: the generic seed patterns of pass 3 (paper § 4.4, DESIGN "Seed selection"), a
//! set of **corner tiles** (Lagae & Dutré 2006) whose borders are seamless for any pair of
//! neighbours, with ranks that thin to blue noise at any density, across borders too.
//!
//! Each pattern covers one ring-0 TLM cell, positions in the unit square [0, 1)². Every lattice
//! corner of the cell grid has one of C colours (a hash of its integer coordinates); a cell shows
//! the pattern of its four corner colours, so there are P = C⁴ patterns (`tlm.patterns`: 1, 16
//! or 81). A pattern is cut into 9 *slots*: four corner quadrants ([0, H)² and its mirrors), four
//! edge halves (along each edge between the corner quadrants, W deep) and the interior (the
//! rest). Its seeds come from pieces that neighbours share:
//! - a **corner patch** per colour, the square [−H, H)² around a lattice corner: its four
//!   quadrants are the corner slots of the four cells meeting there;
//! - an **edge strip** per ordered pair of colours and direction, [H, 1 − H) × [−W, W) along a
//!   horizontal edge (its transpose along a vertical one): its halves are the edge slots of the
//!   two cells on either side; it is built knowing the two corner patches at its ends;
//! - an **interior** per pattern, built knowing its four corner patches and four edge strips.
//!
//! So a point near a corner depends only on that corner's colour and one near an edge only on
//! the edge's two colours: two neighbouring cells agree on everything within W of their border.
//! Pieces that do not know each other never touch: corner patches are 1 − 2H apart, edge strips
//! √2 (H − W), interiors 2W, all 0.29 of a cell (seed spacings are smaller at every density
//! above 5 seeds per cell).
//!
//! **Ranks.** Slot s holds m_s seeds (its area's share of `seeds_per_pattern`, the same in every
//! pattern), and its j-th seed has the priority t = (2j + 1) / 2m_s. A pattern's ranks are its
//! seeds sorted by (t, slot), which is the same order in every pattern, so thinning to rank < k
//! keeps exactly the seeds of t below some τ(k), in every cell alike: the kept set across any
//! border is one progressive point set. Pieces are ranked progressively in priority order
//! (`sampling`: Bridson candidates, then greedy farthest-point choice within the slot, weighing
//! the known pieces' seeds by their priorities), so every prefix is well spread across the
//! pieces' seams as within them. The seams of corner and edge pieces are the cell borders' pieces
//! themselves, so a border costs no spacing.
//!
//! Everything is deterministic: a SplitMix64 stream per piece (world seed, kind, colours), only
//! IEEE-exact operations on coordinates that are multiples of 2^-24. The same seed gives
//! bit-identical patterns on every run and platform; the pieces of each kind are built in
//! parallel, each from its own stream.

mod sampling;
#[cfg(test)]
mod tests;

use rayon::prelude::*;

use sampling::{PieceSpec, Ranked, SplitMix64, build_piece};

/// N r² for the first Bridson radius: a bit under the ≈ 0.6 Bridson reaches, so about 1.09 N points.
const FILL: f64 = 0.55;
/// How much the radius shrinks when a run yields fewer than a slot needs.
const SHRINK: f64 = 0.95;
/// Half the side of a corner patch, in cells (H).
pub const CORNER_HALF: f64 = 0.35;
/// Half the width of an edge strip, in cells (W).
pub const EDGE_HALF: f64 = 0.145;
/// Slots of a pattern: 4 corner quadrants, 4 edge halves (bottom, top, left, right), interior.
const SLOTS: usize = 9;
/// The interior's slot.
const INTERIOR: usize = 8;

/// P generic patterns of blue-noise seed positions, each sorted by rank (index = rank).
#[derive(Debug, Clone, PartialEq)]
pub struct SeedPatterns {
    /// How many patterns there are, P = C⁴ (`tlm.patterns`).
    pub count: u32,
    /// Corner colours C; pattern c₀₀ + C (c₁₀ + C (c₀₁ + C c₁₁)) has corner colours c_xy.
    pub corner_colours: u32,
    /// Seeds in each pattern (`seeds.seeds_per_pattern`); all P patterns hold the same number.
    pub seeds_per_pattern: u32,
    /// pattern p's seed of rank r at p * seeds_per_pattern + r, unit square
    pub positions_unit: Vec<[f32; 2]>,
}

/// The slot of a point of a cell's unit square: corner quadrant cx + 2 cy, edge half 4 + k
/// (bottom, top, left, right), else the interior.
fn slot_of(p: [f64; 2]) -> usize {
    let side = |v: f64| {
        if v < CORNER_HALF {
            Some(0)
        } else if v >= 1.0 - CORNER_HALF {
            Some(1)
        } else {
            None
        }
    };
    match (side(p[0]), side(p[1])) {
        (Some(cx), Some(cy)) => cx + 2 * cy,
        _ if p[1] < EDGE_HALF => 4,
        _ if p[1] >= 1.0 - EDGE_HALF => 5,
        _ if p[0] < EDGE_HALF => 6,
        _ if p[0] >= 1.0 - EDGE_HALF => 7,
        _ => INTERIOR,
    }
}

/// Seeds per slot: each slot's area's share, rounded; the interior takes the remainder.
fn slot_counts(seeds_per_pattern: u32) -> [u32; SLOTS] {
    let n = f64::from(seeds_per_pattern);
    let corner = (n * CORNER_HALF * CORNER_HALF).round() as u32;
    let edge = (n * EDGE_HALF * (1.0 - 2.0 * CORNER_HALF)).round() as u32;
    let mut counts = [corner, corner, corner, corner, edge, edge, edge, edge, 0];
    counts[INTERIOR] = seeds_per_pattern - 4 * (corner + edge);
    counts
}

/// Priority of the j-th seed of a slot of m.
fn priority(j: u32, m: u32) -> f64 {
    f64::from(2 * j + 1) / f64::from(2 * m)
}

/// Every (slot, j) of a pattern in rank order: by priority (exact, on integers), then slot.
fn rank_order(counts: &[u32; SLOTS]) -> Vec<(usize, u32)> {
    let mut order: Vec<(usize, u32)> = (0..SLOTS).flat_map(|s| (0..counts[s]).map(move |j| (s, j))).collect();
    order.sort_by(|&(sa, ja), &(sb, jb)| {
        let a = u64::from(2 * ja + 1) * u64::from(counts[sb]);
        let b = u64::from(2 * jb + 1) * u64::from(counts[sa]);
        a.cmp(&b).then(sa.cmp(&sb))
    });
    order
}

/// A piece: each of its slots is a cell slot seen from the piece's frame shifted by whole cells.
struct Piece {
    /// (cell slot, offset from the piece's frame to that cell's frame).
    slots: Vec<(usize, [f64; 2])>,
}

impl Piece {
    fn corner() -> Self {
        Self { slots: (0..4).map(|s| (s, [(s & 1) as f64, (s >> 1) as f64])).collect() }
    }

    /// Along the edge from (0, 0) to (1, 0): the cell above's bottom half, the cell below's top.
    fn horizontal() -> Self {
        Self { slots: vec![(4, [0.0, 0.0]), (5, [0.0, 1.0])] }
    }

    /// Along the edge from (0, 0) to (0, 1): the cell right's left half, the cell left's right.
    fn vertical() -> Self {
        Self { slots: vec![(6, [0.0, 0.0]), (7, [1.0, 0.0])] }
    }

    fn interior() -> Self {
        Self { slots: vec![(INTERIOR, [0.0, 0.0])] }
    }

    /// The piece's slot of point `p` (piece frame), if it is in the piece.
    fn slot(&self, p: [f64; 2]) -> Option<usize> {
        self.slots.iter().position(|&(cell_slot, o)| {
            let q = [p[0] + o[0], p[1] + o[1]];
            q.iter().all(|v| (0.0..1.0).contains(v)) && slot_of(q) == cell_slot
        })
    }

    /// A box holding the piece, piece frame.
    fn bounds(&self) -> [[f64; 2]; 2] {
        let (h, w) = (CORNER_HALF, EDGE_HALF);
        match self.slots[0].0 {
            0 => [[-h, -h], [h, h]],
            4 => [[h, -w], [1.0 - h, w]],
            6 => [[-w, h], [w, 1.0 - h]],
            _ => [[0.0, 0.0], [1.0, 1.0]],
        }
    }

    /// Builds the piece knowing `known` (piece frame): per piece slot, its seeds in order.
    fn build(
        &self,
        counts: &[u32; SLOTS],
        order: &[(usize, u32)],
        known: &[Ranked],
        n: u32,
        stream: u64,
    ) -> Built {
        let schedule = order
            .iter()
            .filter_map(|&(s, j)| {
                let slot = self.slots.iter().position(|&(cell_slot, _)| cell_slot == s)?;
                Some((slot, j, priority(j, counts[s])))
            })
            .collect();
        let slot_of = |p: [f64; 2]| self.slot(p);
        let spec = PieceSpec {
            bounds: self.bounds(),
            slot_of: &slot_of,
            counts: self.slots.iter().map(|&(s, _)| counts[s]).collect(),
            schedule,
        };
        let mut rng = SplitMix64(stream.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ 0x5eed_5eed_5eed_5eed);
        let seeds = build_piece(&spec, known, n, &mut rng);
        Built { slots: self.slots.clone(), seeds, counts: spec.counts }
    }
}

/// A built piece: its slots (cell slot, offset) and each slot's seeds in priority order.
struct Built {
    slots: Vec<(usize, [f64; 2])>,
    seeds: Vec<Vec<[f64; 2]>>,
    counts: Vec<u32>,
}

impl Built {
    /// Its seeds with their priorities, shifted by `by` into another piece's frame.
    fn known(&self, by: [f64; 2]) -> impl Iterator<Item = Ranked> + '_ {
        self.seeds.iter().zip(&self.counts).flat_map(move |(seeds, &m)| {
            seeds
                .iter()
                .enumerate()
                .map(move |(j, p)| Ranked { p: [p[0] + by[0], p[1] + by[1]], t: priority(j as u32, m) })
        })
    }

    /// The seeds of cell slot `cell_slot`, in the cell's frame.
    fn cell_seeds(&self, cell_slot: usize) -> Vec<[f64; 2]> {
        let Some(k) = self.slots.iter().position(|&(s, _)| s == cell_slot) else { return Vec::new() };
        let o = self.slots[k].1;
        self.seeds[k].iter().map(|p| [p[0] + o[0], p[1] + o[1]]).collect()
    }
}

/// The corner colours of pattern `p` of C: (c₀₀, c₁₀, c₀₁, c₁₁).
pub fn corner_colours_of(p: u32, colours: u32) -> [u32; 4] {
    let c = colours.max(1);
    [p % c, (p / c) % c, (p / (c * c)) % c, (p / (c * c * c)) % c]
}

impl SeedPatterns {
    /// The C⁴ patterns of `corner_colours` colours, `seeds_per_pattern` seeds each, from the
    /// germ `seed`.
    pub fn generate(corner_colours: u32, seeds_per_pattern: u32, seed: u32) -> Self {
        let c = corner_colours;
        let count = c.pow(4);
        let n = seeds_per_pattern;
        let counts = slot_counts(n);
        let order = rank_order(&counts);
        let stream = |kind: u64, index: u32| (u64::from(seed) << 32) ^ (kind << 24) ^ u64::from(index);
        let corners: Vec<Built> = (0..c)
            .into_par_iter()
            .map(|k| Piece::corner().build(&counts, &order, &[], n, stream(1, k)))
            .collect();
        // Edge strips: index a + C b + C² direction, from corner colour a to corner colour b.
        let edges: Vec<Built> = (0..2 * c * c)
            .into_par_iter()
            .map(|e| {
                let (a, b, vertical) = (e % c, (e / c) % c, e >= c * c);
                let (piece, far) = if vertical {
                    (Piece::vertical(), [0.0, 1.0])
                } else {
                    (Piece::horizontal(), [1.0, 0.0])
                };
                let known: Vec<Ranked> =
                    corners[a as usize].known([0.0, 0.0]).chain(corners[b as usize].known(far)).collect();
                piece.build(&counts, &order, &known, n, stream(2, e))
            })
            .collect();
        let edge =
            |a: u32, b: u32, vertical: bool| &edges[(a + c * b + if vertical { c * c } else { 0 }) as usize];
        let positions_unit = (0..count)
            .into_par_iter()
            .map(|p| {
                let [c00, c10, c01, c11] = corner_colours_of(p, c);
                let corner_at = [(c00, [0.0, 0.0]), (c10, [1.0, 0.0]), (c01, [0.0, 1.0]), (c11, [1.0, 1.0])];
                let edge_at = [
                    (edge(c00, c10, false), [0.0, 0.0]),
                    (edge(c01, c11, false), [0.0, 1.0]),
                    (edge(c00, c01, true), [0.0, 0.0]),
                    (edge(c10, c11, true), [1.0, 0.0]),
                ];
                let known: Vec<Ranked> = corner_at
                    .iter()
                    .flat_map(|&(k, at)| corners[k as usize].known(at))
                    .chain(edge_at.iter().flat_map(|&(e, at)| e.known(at)))
                    .collect();
                let interior = Piece::interior().build(&counts, &order, &known, n, stream(3, p));
                // Each cell slot's seeds, from the piece that holds it.
                let mut slots: Vec<Vec<[f64; 2]>> = (0..4)
                    .map(|s| {
                        let (k, _) = corner_at[s];
                        corners[k as usize].cell_seeds(s)
                    })
                    .collect();
                slots.extend((0..4).map(|k| edge_at[k].0.cell_seeds(4 + k)));
                slots.push(interior.cell_seeds(INTERIOR));
                order.iter().map(|&(s, j)| slots[s][j as usize].map(|v| v as f32)).collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
            .concat();
        Self { count, corner_colours: c, seeds_per_pattern: n, positions_unit }
    }

    /// Pattern `p`'s seeds in rank order (empty for p ≥ count).
    pub fn pattern(&self, p: u32) -> &[[f32; 2]] {
        let n = self.seeds_per_pattern as usize;
        let start = p as usize * n;
        self.positions_unit.get(start..start + n).unwrap_or(&[])
    }
}
