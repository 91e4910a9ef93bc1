//! The tile set's promises: deterministic and sized; ranks in the same slots in every pattern;
//! every prefix blue noise over a field of cells with hashed corners, as spaced across borders
//! as inside; a single-colour pattern tiling against itself.

use super::*;
use crate::seeds::cell_pattern;
use crate::seeds::spacing::{BorderSpacing, quantile};

/// Least distance of the closest pair of a prefix of k seeds a cell, in 1 / √k: measured
/// 0.498–0.742 over the prefixes (docs/seeds.md), a margin under the least; neighbours that share
/// no border piece put a pair closer (the control below).
const MIN_CLOSEST_PAIR: f64 = 0.45;
/// Most any point of the inner cells may lie from its nearest seed, in 1 / √k: measured at most
/// 1.01; a third more is a hole where a seed is missing.
const MAX_COVERAGE: f64 = 1.35;
/// Least 1st-percentile nearest neighbour across a border over inside a cell: a seamless process
/// gives about 1; independent neighbours gave 0.24–0.32 (docs/seeds.md, "before").
const MIN_BORDER_RATIO: f64 = 0.9;

fn d2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// The seeds of rank < `k` of a `side` × `side` field of cells (corner colours hashed as the
/// TLM does), in cell units, with their cells.
fn field(patterns: &SeedPatterns, side: i32, k: usize) -> (Vec<[f64; 2]>, Vec<[i64; 2]>) {
    field_of(&[patterns], side, k)
}

/// The same, with the cells taking their patterns from the sets in turn, like a checkerboard: with
/// two sets generated apart, no cell's neighbours share its border pieces (the controls).
fn field_of(sets: &[&SeedPatterns], side: i32, k: usize) -> (Vec<[f64; 2]>, Vec<[i64; 2]>) {
    let (mut xy, mut cells) = (Vec::new(), Vec::new());
    for y in 0..side {
        for x in 0..side {
            let patterns = sets[(x + y) as usize % sets.len()];
            let p = cell_pattern([x - side / 2, y - side / 2], 1, patterns.corner_colours);
            for s in &patterns.pattern(p)[..k] {
                xy.push([f64::from(x) + f64::from(s[0]), f64::from(y) + f64::from(s[1])]);
                cells.push([i64::from(x), i64::from(y)]);
            }
        }
    }
    (xy, cells)
}

#[test]
fn patterns_are_deterministic_and_sized() {
    let a = SeedPatterns::generate(2, 256, 7);
    assert_eq!(a, SeedPatterns::generate(2, 256, 7));
    assert_ne!(a.positions_unit, SeedPatterns::generate(2, 256, 8).positions_unit);
    assert_eq!(a.positions_unit.len(), 16 * 256);
    assert_eq!((a.count, a.corner_colours, a.seeds_per_pattern), (16, 2, 256));
    assert!(a.positions_unit.iter().flatten().all(|&v| (0.0..1.0).contains(&v)));
    for p in 0..16 {
        assert_eq!(a.pattern(p).len(), 256);
        for q in 0..p {
            assert_ne!(a.pattern(p), a.pattern(q), "patterns {p} and {q}");
        }
    }
    assert!(a.pattern(16).is_empty());
    assert!(SeedPatterns::generate(0, 256, 1).positions_unit.is_empty());
    assert_eq!(SeedPatterns::generate(1, 1, 1).positions_unit.len(), 1);
    assert_eq!(SeedPatterns::generate(1, 3, 1).positions_unit.len(), 3);
    assert_eq!(SeedPatterns::generate(3, 64, 1).positions_unit.len(), 81 * 64);
}

#[test]
fn a_rank_lies_in_the_same_slot_of_every_pattern() {
    // What makes thinning by rank consistent across borders: rank r is the same (slot, j).
    let a = SeedPatterns::generate(2, 512, 3);
    let slots = |p: u32| a.pattern(p).iter().map(|s| slot_of(s.map(f64::from))).collect::<Vec<_>>();
    let first = slots(0);
    for p in 1..a.count {
        assert_eq!(slots(p), first, "pattern {p}");
    }
    let counts = slot_counts(512);
    for (s, &count) in counts.iter().enumerate() {
        assert_eq!(first.iter().filter(|&&k| k == s).count(), count as usize, "slot {s}");
    }
}

#[test]
fn neighbours_share_their_border_pieces() {
    // Cells (0, 0) and (1, 0) share the edge strip between corners (1, 0) and (1, 1): the right
    // half of one and the left half of the other come from one piece, so the union of the two
    // near the border is one Poisson-disk set: no pair closer than the candidates' radius.
    let a = SeedPatterns::generate(2, 1024, 5);
    let (xy, cells) = field(&a, 8, 1024);
    let r = (FILL / 1024.0).sqrt() * SHRINK.powi(3);
    for (i, p) in xy.iter().enumerate() {
        for (j, q) in xy.iter().enumerate().skip(i + 1) {
            if cells[i] != cells[j] && d2(*p, *q) < r * r {
                panic!(
                    "seeds {p:?} and {q:?} of cells {:?} and {:?} are {:.4} apart",
                    cells[i],
                    cells[j],
                    d2(*p, *q).sqrt()
                );
            }
        }
    }
}

#[test]
fn every_prefix_is_blue_noise_across_borders() {
    let n = 1024;
    let patterns = SeedPatterns::generate(2, n, 1);
    let side = 8;
    for k in [8, n / 64, n / 16, n / 4, n / 2, n] {
        let (xy, cells) = field(&patterns, side, k as usize);
        let scale = f64::from(k).sqrt();
        let s = BorderSpacing::of(&xy, &cells, 1.0);
        let closest = quantile(&s.across, 0.0).min(quantile(&s.inside, 0.0)) * scale;
        // Coverage: the farthest probe of the inner 6 × 6 cells from its nearest seed.
        let mut cover: f64 = 0.0;
        for j in 0..96 {
            for i in 0..96 {
                let probe = [1.0 + (f64::from(i) + 0.5) / 16.0, 1.0 + (f64::from(j) + 0.5) / 16.0];
                let near = xy.iter().map(|&p| d2(p, probe)).fold(f64::INFINITY, f64::min);
                cover = cover.max(near.sqrt() * scale);
            }
        }
        println!(
            "k = {k}: closest pair {closest:.3} / √k, coverage {cover:.3} / √k, 1st-percentile ratio across / inside {:.3}",
            s.ratio()
        );
        // Real distances: a duplicated seed would make the inside quantile 0 and the ratio ∞.
        assert!(
            quantile(&s.inside, 0.01) > 0.0 && !s.across.is_empty(),
            "k = {k}: {} across",
            s.across.len()
        );
        assert!(closest >= MIN_CLOSEST_PAIR, "k = {k}: closest pair {closest:.3} / √k");
        assert!(cover <= MAX_COVERAGE, "k = {k}: coverage {cover:.3} / √k");
        assert!(s.ratio() >= MIN_BORDER_RATIO, "k = {k}: across / inside {:.3}", s.ratio());
    }
}

#[test]
fn neighbours_that_share_no_border_pieces_fail_the_spacing_bounds() {
    // Control of the test above: the same field with every cell's neighbours taken from a set
    // generated apart, so that no border piece is shared, as the torus patterns were.
    let n = 1024;
    let (a, b) = (SeedPatterns::generate(2, n, 1), SeedPatterns::generate(2, n, 2));
    let (xy, cells) = field_of(&[&a, &b], 8, n as usize);
    let s = BorderSpacing::of(&xy, &cells, 1.0);
    let closest = quantile(&s.across, 0.0) * f64::from(n).sqrt();
    println!("independent neighbours: closest pair across {closest:.3} / √k, ratio {:.3}", s.ratio());
    assert!(closest < MIN_CLOSEST_PAIR && s.ratio() < MIN_BORDER_RATIO, "{closest}, {}", s.ratio());
}

#[test]
fn one_colour_tiles_against_itself() {
    let a = SeedPatterns::generate(1, 512, 3);
    assert_eq!(a.count, 1);
    let (xy, cells) = field(&a, 3, 512);
    let s = BorderSpacing::of(&xy, &cells, 1.0);
    let closest = quantile(&s.across, 0.0);
    assert!(closest * 512f64.sqrt() >= 0.5, "{closest}");
}

#[test]
fn the_accurate_presets_patterns_are_generated_whole() {
    // How long it takes is `benches/patterns.rs`'s to say, not a test's.
    let patterns = SeedPatterns::generate(2, 4096, 1);
    assert_eq!(patterns.positions_unit.len(), 16 * 4096);
}
