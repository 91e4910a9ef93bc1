//! How it works: the trees of a forest sample, placed by dart throwing (Poisson disk) over the
//! sample's square, which wraps like a torus, under the tiles' boundary conditions (Decaudin &
//! Neyret § 7): a tree whose crown crosses an edge of the sample's triangles is placed on every
//! *twin* of that edge (same direction, same colour, `texcell::tiling::REFERENCE`) at the same
//! place relative to it, so any two tiles that meet on an edge of that colour show the same trees
//! across it; a crown that would cross two edges (near a corner) is refused, as it would tie them
//! together. Every tree keeps `spacing_m` from every other (the sample wraps). Species come by the
//! class's densities, heights uniformly from their ranges, as the seeds draw theirs.

use glam::Vec2;

use crate::seeds::pcg;
use crate::texcell::SampleTree;
use crate::texcell::tiling::{REFERENCE, REFERENCE_CELLS};

/// A species the class grows, as the sample places it.
#[derive(Debug, Clone, PartialEq)]
pub struct Grown {
    /// Its model's name.
    pub model: String,
    /// Its share of the class's seeds (the class's seeds per km²).
    pub per_km2: f32,
    /// The range its height is drawn from, metres.
    pub height_m: [f32; 2],
    /// Its crown's horizontal radius per metre of height, from its mesh.
    pub crown_per_height: f32,
}

/// One edge of the sample's triangles: direction (0 horizontal, 1 vertical, 2 diagonal), colour,
/// and its ends (metres).
#[derive(Debug, Clone, Copy)]
struct Edge {
    direction: u32,
    colour: u32,
    from: Vec2,
    to: Vec2,
}

/// The sample's twelve edges: each cell's bottom, left side and diagonal.
fn edges(cell_m: f32) -> Vec<Edge> {
    let n = REFERENCE_CELLS;
    let mut out = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let i = (x + n * y) as usize;
            let corner = Vec2::new(x as f32, y as f32) * cell_m;
            let r = &REFERENCE;
            out.push(Edge {
                direction: 0,
                colour: r.horizontal[i],
                from: corner,
                to: corner + Vec2::X * cell_m,
            });
            out.push(Edge {
                direction: 1,
                colour: r.vertical[i],
                from: corner,
                to: corner + Vec2::Y * cell_m,
            });
            out.push(Edge {
                direction: 2,
                colour: r.diagonal[i],
                from: corner,
                to: corner + Vec2::ONE * cell_m,
            });
        }
    }
    out
}

/// `p` wrapped into the sample's square [0, side)².
fn wrap(p: Vec2, side_m: f32) -> Vec2 {
    Vec2::new(p.x.rem_euclid(side_m), p.y.rem_euclid(side_m))
}

/// The image of `p` (wrapping) nearest to `q`.
fn nearest_image(p: Vec2, q: Vec2, side_m: f32) -> Vec2 {
    let d = p - q;
    q + d - (d / side_m).round() * side_m
}

/// Distance from `p` to the segment [a, b].
fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    (a + ab * t - p).length()
}

/// The stream of numbers in [0, 1) of the placement.
struct Stream(u32);

impl Stream {
    fn next(&mut self) -> f32 {
        self.0 = pcg(self.0);
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// Places trees of `grown` over the sample of `cell_m` cells (side `REFERENCE_CELLS · cell_m`),
/// aiming at `per_m2` trees per square metre, no two closer than `spacing_m`, from the germ
/// `seed`. Fewer when the darts run out (after 200 per tree aimed at).
pub fn place(grown: &[Grown], cell_m: f32, per_m2: f32, spacing_m: f32, seed: u32) -> Vec<SampleTree> {
    let side_m = REFERENCE_CELLS as f32 * cell_m;
    let target = (per_m2 * side_m * side_m).round() as usize;
    let total: f32 = grown.iter().map(|g| g.per_km2).sum();
    if target == 0 || grown.is_empty() || total <= 0.0 {
        return Vec::new();
    }
    let edges = edges(cell_m);
    let mut stream = Stream(pcg(seed ^ 0x5eed_f0e5));
    let mut trees: Vec<SampleTree> = Vec::new();
    let mut at: Vec<Vec2> = Vec::new();
    for _ in 0..200 * target {
        if trees.len() >= target {
            break;
        }
        let p = Vec2::new(stream.next(), stream.next()) * side_m;
        let pick = stream.next() * total;
        let mut sum = 0.0;
        let g = grown
            .iter()
            .find(|g| {
                sum += g.per_km2;
                pick < sum
            })
            .unwrap_or(&grown[grown.len() - 1]);
        let height_m = g.height_m[0] + (g.height_m[1] - g.height_m[0]) * stream.next();
        let angle_deg = 360.0 * stream.next();
        let crown_m = height_m * g.crown_per_height;
        // The edges the crown crosses (wrapping): none, or one and its twins.
        let crossed: Vec<(&Edge, Vec2)> = edges
            .iter()
            .map(|e| (e, nearest_image(p, (e.from + e.to) * 0.5, side_m)))
            .filter(|(e, q)| segment_distance(*q, e.from, e.to) < crown_m)
            .collect();
        let copies: Vec<Vec2> = match crossed.as_slice() {
            [] => vec![p],
            [(edge, q)] => edges
                .iter()
                .filter(|e| e.direction == edge.direction && e.colour == edge.colour)
                .map(|e| wrap(*q - edge.from + e.from, side_m))
                .collect(),
            _ => continue,
        };
        let free = copies
            .iter()
            .all(|&c| at.iter().all(|&o| (nearest_image(o, c, side_m) - c).length() >= spacing_m));
        if !free {
            continue;
        }
        for c in copies {
            at.push(c);
            trees.push(SampleTree { model: g.model.clone(), position_m: c.to_array(), height_m, angle_deg });
        }
    }
    trees
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pine() -> Grown {
        Grown { model: "Pine_1".into(), per_km2: 1.0, height_m: [8.0, 20.0], crown_per_height: 0.25 }
    }

    #[test]
    fn trees_crossing_an_edge_stand_on_its_twins_too() {
        let cell_m = 32.0;
        let trees = place(&[pine()], cell_m, 0.015, 4.5, 3);
        let side_m = 2.0 * cell_m;
        // Close to the density aimed at (61 trees on 64 m × 64 m).
        assert!((50..=62).contains(&trees.len()), "{}", trees.len());
        let edges = edges(cell_m);
        let mut crossing = 0;
        for t in &trees {
            let p = Vec2::from(t.position_m);
            let crown = t.height_m * 0.25;
            let crossed: Vec<&Edge> = edges
                .iter()
                .filter(|e| {
                    segment_distance(nearest_image(p, (e.from + e.to) * 0.5, side_m), e.from, e.to) < crown
                })
                .collect();
            assert!(crossed.len() <= 1, "a crown crosses {} edges", crossed.len());
            let Some(edge) = crossed.first() else { continue };
            crossing += 1;
            // On every twin edge, a tree of the same model, height and turn at the same place.
            let q = nearest_image(p, (edge.from + edge.to) * 0.5, side_m) - edge.from;
            for twin in edges.iter().filter(|e| e.direction == edge.direction && e.colour == edge.colour) {
                let want = wrap(q + twin.from, side_m);
                assert!(
                    trees.iter().any(|o| (nearest_image(Vec2::from(o.position_m), want, side_m) - want)
                        .length()
                        < 1e-3
                        && o.height_m == t.height_m
                        && o.angle_deg == t.angle_deg),
                    "no twin of {t:?} at {want}"
                );
            }
        }
        assert!(crossing >= 8, "only {crossing} trees cross an edge: a weak test");
        // Spacing, wrapping included.
        for (i, a) in trees.iter().enumerate() {
            for b in &trees[i + 1..] {
                let (pa, pb) = (Vec2::from(a.position_m), Vec2::from(b.position_m));
                assert!((nearest_image(pa, pb, side_m) - pb).length() >= 4.5 - 1e-4);
            }
        }
        // Deterministic from the germ, another germ another forest.
        assert_eq!(place(&[pine()], cell_m, 0.015, 4.5, 3), trees);
        assert_ne!(place(&[pine()], cell_m, 0.015, 4.5, 4), trees);
    }

    #[test]
    fn species_come_by_their_densities() {
        let oak = Grown { model: "Tree_1".into(), per_km2: 3.0, ..pine() };
        let trees = place(&[pine(), oak], 64.0, 0.01, 3.0, 9);
        let oaks = trees.iter().filter(|t| t.model == "Tree_1").count() as f32;
        let share = oaks / trees.len() as f32;
        assert!(trees.len() > 100 && (0.65..=0.85).contains(&share), "{} trees, {share} oaks", trees.len());
        assert!(trees.iter().all(|t| (8.0..=20.0).contains(&t.height_m)));
        assert!(place(&[], 32.0, 0.01, 3.0, 1).is_empty());
    }
}
