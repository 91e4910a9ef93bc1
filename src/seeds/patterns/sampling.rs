//! How it works: the two steps that make every piece of the tile set (`super`), in the piece's own
//! frame. A piece is built after the pieces it borders (its *known* points, each with its
//! priority t in (0, 1)), so it can respect them; it never sees the pieces built after it.
//!
//! 1. **Poisson-disk candidates** by Bridson's algorithm (SIGGRAPH sketch 2007) inside the
//!    piece's region: a candidate closer than r to a known point or to an earlier candidate is
//!    refused, so the union of a piece with its known neighbours is a Poisson-disk set. Annulus
//!    samples come by rejection from a square; when the active list runs dry a few darts are
//!    thrown at the whole region, so no pocket stays empty. Bridson with 30 attempts fills the
//!    plane at N r² ≈ 0.6, so r = √(0.55 / N) gives about 1.09 candidates per seed wanted.
//! 2. **Progressive ranking**: the piece's seeds are chosen one priority at a time, in the order
//!    of the tile schedule (each slot, a region of the piece, gets its j-th seed at
//!    t = (2j + 1) / 2m, m being the slot's count). At priority t the slot's candidate chosen is
//!    the one farthest from what is there: its squared distance to each seed already chosen in
//!    the piece, and to each known point q weighted by clamp(t_q / t, 1, 2). A known point of a
//!    lower priority counts in full (it is kept whenever this seed is); one of a higher
//!    priority counts less, the later it comes (a pair is only ever kept together at densities
//!    where the later one is kept, whose spacing is smaller): a seed placed now does not crowd
//!    the known seeds of later priorities either. (Measured over fields of 8 × 8 cells of 2048
//!    seeds, 3 germs: a cap of 2 leaves the closest pair of 16 seeds per cell 0.54–0.58 / √k
//!    apart, a cap of 4 0.52–0.55; at 64 and more seeds per cell they agree.) That weighted distance only shrinks as t grows
//!    and seeds are added, so a lazy max-heap per slot (pop, re-evaluate, keep it if it still
//!    beats the next) chooses exactly the farthest, as greedy farthest-point ordering would. A
//!    bucket grid about r wide answers each evaluation, ring by ring, stopping at the first ring
//!    that cannot beat the best so far.
//!
//! Every coordinate is a multiple of 2^-24 (rounded down), so shifting a piece by whole tiles
//! and storing a tile's seeds as f32 in [0, 1) are exact. Only IEEE-exact operations (+, −, ×, ÷,
//! √, floor, rounding casts) and a SplitMix64 stream are used: the result is the same on every
//! platform.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Bridson's attempts around an active point before it retires (his k).
const ATTEMPTS: u32 = 30;
/// Darts thrown at the whole region once the active list is empty, before giving up.
const DARTS: u32 = 64;
/// How much more a known point of a later priority may count, at most (see the header).
const LATER_WEIGHT: f64 = 2.0;
/// Coordinates are multiples of 1 / QUANTUM.
const QUANTUM: f64 = 16_777_216.0;

/// SplitMix64 (Steele, Lea & Flood 2014): tiny, fast, and the same on every platform.
pub(super) struct SplitMix64(pub(super) u64);

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

/// `x` rounded down to a multiple of 2^-24 (exact: scaling by a power of two, floor).
pub(super) fn quantise(x: f64) -> f64 {
    (x * QUANTUM).floor() * (1.0 / QUANTUM)
}

/// A point of a piece or of its known neighbours, with its priority (0: chosen in this piece).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Ranked {
    /// Position in the frame of the piece being built.
    pub(super) p: [f64; 2],
    /// Priority t in (0, 1): kept at every density whose schedule reaches t.
    pub(super) t: f64,
}

fn d2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

/// Points bucketed on a square grid over a box (points outside it go to its edge buckets, which
/// only makes them look nearer than they are: the ring bounds stay true).
struct Buckets {
    lo: [f64; 2],
    size: f64,
    side: [usize; 2],
    cells: Vec<Vec<u32>>,
    points: Vec<Ranked>,
}

impl Buckets {
    fn new(lo: [f64; 2], hi: [f64; 2], size: f64) -> Self {
        let side = [0, 1].map(|a| (((hi[a] - lo[a]) / size).ceil() as usize).max(1));
        Self { lo, size, side, cells: vec![Vec::new(); side[0] * side[1]], points: Vec::new() }
    }

    fn cell_of(&self, p: [f64; 2]) -> [usize; 2] {
        [0, 1].map(|a| (((p[a] - self.lo[a]) / self.size).max(0.0) as usize).min(self.side[a] - 1))
    }

    fn insert(&mut self, r: Ranked) {
        let [x, y] = self.cell_of(r.p);
        self.cells[y * self.side[0] + x].push(self.points.len() as u32);
        self.points.push(r);
    }

    /// Calls `f` with each point of the square ring `ring` (in buckets) around `c`.
    fn ring(&self, c: [usize; 2], ring: usize, mut f: impl FnMut(&Ranked)) {
        let (cx, cy) = (c[0] as isize, c[1] as isize);
        let r = ring as isize;
        for y in cy - r..=cy + r {
            if y < 0 || y >= self.side[1] as isize {
                continue;
            }
            let edge = y == cy - r || y == cy + r;
            let step = if edge || r == 0 { 1 } else { 2 * r as usize };
            for x in (cx - r..=cx + r).step_by(step) {
                if x >= 0 && x < self.side[0] as isize {
                    for &i in &self.cells[y as usize * self.side[0] + x as usize] {
                        f(&self.points[i as usize]);
                    }
                }
            }
        }
    }

    /// Whether a point lies closer than √`r2` to `p` (`r2` at most one bucket, squared).
    fn any_within(&self, p: [f64; 2], r2: f64) -> bool {
        let c = self.cell_of(p);
        let mut any = false;
        for ring in 0..2 {
            self.ring(c, ring, |q| any = any || d2(q.p, p) < r2);
        }
        any
    }

    /// min over stored points q of |p − q|² × clamp(t_q / t, 1, LATER_WEIGHT), or `bound` if
    /// none is below it.
    fn weighted_nearest(&self, p: [f64; 2], t: f64, bound: f64) -> f64 {
        let c = self.cell_of(p);
        let rings = self.side[0].max(self.side[1]);
        let mut best = bound;
        for ring in 0..=rings {
            // Every point of this ring or beyond is at least (ring − 1) buckets away.
            let floor = ring.saturating_sub(1) as f64 * self.size;
            if floor * floor >= best {
                break;
            }
            self.ring(c, ring, |q| {
                let w = if q.t <= t { 1.0 } else { (q.t / t).min(LATER_WEIGHT) };
                best = best.min(d2(q.p, p) * w);
            });
        }
        best
    }
}

/// A piece to build: its bounding box, which slot (if any) holds a point, and each slot's
/// schedule, in priority order.
pub(super) struct PieceSpec<'a> {
    /// Lower and upper corner of a box holding every slot.
    pub(super) bounds: [[f64; 2]; 2],
    /// The slot of a point, `None` outside the piece.
    pub(super) slot_of: &'a dyn Fn([f64; 2]) -> Option<usize>,
    /// Seeds per slot.
    pub(super) counts: Vec<u32>,
    /// The slots' events (slot, j, t) in schedule order, for every slot.
    pub(super) schedule: Vec<(usize, u32, f64)>,
}

/// Builds a piece: per slot, its seeds in schedule order (the j-th has the j-th priority).
pub(super) fn build_piece(
    spec: &PieceSpec,
    known: &[Ranked],
    seeds_per_pattern: u32,
    rng: &mut SplitMix64,
) -> Vec<Vec<[f64; 2]>> {
    let mut radius = (super::FILL / f64::from(seeds_per_pattern.max(1))).sqrt();
    loop {
        let candidates = bridson(spec, known, radius, rng);
        let mut per_slot = vec![0u32; spec.counts.len()];
        for &(_, slot) in &candidates {
            per_slot[slot] += 1;
        }
        if per_slot.iter().zip(&spec.counts).all(|(have, want)| have >= want) {
            return rank(spec, known, &candidates, radius);
        }
        radius *= super::SHRINK;
    }
}

/// Bridson's Poisson-disk candidates of the piece at `radius`, with their slots.
fn bridson(spec: &PieceSpec, known: &[Ranked], radius: f64, rng: &mut SplitMix64) -> Vec<([f64; 2], usize)> {
    let r2 = radius * radius;
    let [lo, hi] = spec.bounds;
    let mut grid = Buckets::new(lo, hi, radius);
    for &k in known {
        grid.insert(k);
    }
    let mut points: Vec<([f64; 2], usize)> = Vec::new();
    let mut active: Vec<u32> = Vec::new();
    let mut darts = 0;
    let place = |p: [f64; 2], grid: &Buckets| -> Option<usize> {
        (spec.slot_of)(p).filter(|_| !grid.any_within(p, r2))
    };
    while darts < DARTS {
        if active.is_empty() {
            let p = [0, 1].map(|a| quantise(lo[a] + rng.unit() * (hi[a] - lo[a])));
            darts += 1;
            if let Some(slot) = place(p, &grid) {
                active.push(points.len() as u32);
                points.push((p, slot));
                grid.insert(Ranked { p, t: 0.0 });
            }
            continue;
        }
        let slot = rng.below(active.len());
        let centre = points[active[slot] as usize].0;
        let mut found = false;
        for _ in 0..ATTEMPTS {
            let (dx, dy) = ((rng.unit() * 4.0 - 2.0) * radius, (rng.unit() * 4.0 - 2.0) * radius);
            let dd = dx * dx + dy * dy;
            if dd < r2 || dd >= 4.0 * r2 {
                continue;
            }
            let p = [quantise(centre[0] + dx), quantise(centre[1] + dy)];
            if let Some(s) = place(p, &grid) {
                active.push(points.len() as u32);
                points.push((p, s));
                grid.insert(Ranked { p, t: 0.0 });
                found = true;
                break;
            }
        }
        if !found {
            active.swap_remove(slot);
        }
    }
    points
}

/// The progressive choice of each slot's seeds among `candidates` (see the header).
fn rank(
    spec: &PieceSpec,
    known: &[Ranked],
    candidates: &[([f64; 2], usize)],
    radius: f64,
) -> Vec<Vec<[f64; 2]>> {
    let [lo, hi] = spec.bounds;
    let mut grid = Buckets::new(lo, hi, radius);
    for &k in known {
        grid.insert(k);
    }
    // Max-heaps of (upper bound of the weighted squared distance, smallest index first).
    let mut heaps: Vec<BinaryHeap<(u64, Reverse<u32>)>> = vec![BinaryHeap::new(); spec.counts.len()];
    for (i, &(_, slot)) in candidates.iter().enumerate() {
        heaps[slot].push((f64::INFINITY.to_bits(), Reverse(i as u32)));
    }
    let mut chosen: Vec<Vec<[f64; 2]>> =
        spec.counts.iter().map(|&m| Vec::with_capacity(m as usize)).collect();
    for &(slot, _, t) in &spec.schedule {
        let heap = &mut heaps[slot];
        while let Some((bound, Reverse(i))) = heap.pop() {
            let p = candidates[i as usize].0;
            let score = grid.weighted_nearest(p, t, f64::from_bits(bound)).to_bits();
            if heap.peek().is_none_or(|&top| (score, Reverse(i)) >= top) {
                chosen[slot].push(p);
                grid.insert(Ranked { p, t: 0.0 });
                break;
            }
            heap.push((score, Reverse(i)));
        }
    }
    chosen
}
