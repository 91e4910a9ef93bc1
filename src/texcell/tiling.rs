//! How it works: the aperiodic mapping of a forest sample onto the ground (Decaudin & Neyret 2004,
//! § 7, after Neyret & Cani 1999). The ground is cut into square cells of `cell_m`, each split by
//! its south-west–north-east diagonal into a *lower* triangle (south-east of the diagonal) and an
//! *upper* one (north-west): three edge directions, as in a triangular lattice. Every edge carries
//! a colour, 0 or 1, and a triangle's *triplet* is the colours of its horizontal, vertical and
//! diagonal edges. Two triangles that share an edge see the same colour on it, so any two tiles
//! drawn side by side agree on that edge when the forest sample is built to (a tree crossing an
//! edge is repeated on every edge of that direction and colour, its *twins*).
//!
//! Eight tiles suffice, as in the paper: lower triangles only ever get triplets of even parity
//! (h ⊕ v ⊕ d = 0) and upper ones odd. That holds when the four outer edges of every cell have an
//! odd sum (then the diagonal's colour, set from the lower triangle's, gives the upper one odd
//! parity), which a local rule guarantees: each lattice vertex gets a colour bit by a hash of its
//! position and the world's germ, a vertical edge the sum of its ends', a horizontal edge the sum
//! of its ends' plus its row's parity (a cell's four edges then sum to the two rows' parities, 1).
//!
//! The sample itself is `REFERENCE_CELLS`² cells whose edges (`REFERENCE`) hold each of the eight
//! triplets exactly once, wrapping like a torus: every triangle's neighbours in the sample are
//! compatible tiles, so filtering across a tile's border reads colour that belongs there. A ground
//! triangle shows the sample's triangle of the same half and triplet (`sample_cell`).

use crate::seeds::pcg;

/// Which half of its cell a triangle is: south-east or north-west of the cell's SW–NE diagonal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Half {
    /// South-east of the diagonal (x − x₀ > y − y₀): its edges are the cell's bottom, right side
    /// and diagonal.
    Lower,
    /// North-west of the diagonal: the cell's top, left side and diagonal.
    Upper,
}

/// A triangle's edge colours: horizontal (bit 0), vertical (bit 1) and diagonal (bit 2).
pub type Triplet = u32;

/// The triplet of edge colours `h`, `v`, `d` (each 0 or 1).
pub const fn triplet(h: u32, v: u32, d: u32) -> Triplet {
    (h & 1) | ((v & 1) << 1) | ((d & 1) << 2)
}

/// Cells along each side of the forest sample.
pub const REFERENCE_CELLS: u32 = crate::gpu::layout::TEXCELL_REFERENCE_CELLS;

/// The forest sample's edge colours, each indexed by cell (x + `REFERENCE_CELLS` · y), the sample
/// wrapping around: `horizontal` the cell's bottom edge (its top is the bottom of the cell above),
/// `vertical` its left edge (its right is the left of the cell to its right), `diagonal` its own.
pub struct ReferenceEdges {
    /// Bottom edge of each cell.
    pub horizontal: [u32; 4],
    /// Left edge of each cell.
    pub vertical: [u32; 4],
    /// Diagonal of each cell.
    pub diagonal: [u32; 4],
}

/// Found by enumerating the 2¹² colourings of a 2 × 2 torus: lower triplets (0,1,1), (1,0,1),
/// (0,0,0), (1,1,0); upper (0,0,1), (1,1,1), (0,1,0), (1,0,0) (`tests`).
pub const REFERENCE: ReferenceEdges =
    ReferenceEdges { horizontal: [0, 1, 0, 1], vertical: [0, 1, 1, 0], diagonal: [1, 1, 0, 0] };

fn wrap(i: i64) -> usize {
    i.rem_euclid(i64::from(REFERENCE_CELLS)) as usize
}

fn reference_index(x: i64, y: i64) -> usize {
    wrap(x) + REFERENCE_CELLS as usize * wrap(y)
}

/// The triplet of the sample's triangle `half` of cell (`x`, `y`) (wrapping).
pub fn reference_triplet(x: i64, y: i64, half: Half) -> Triplet {
    let r = &REFERENCE;
    let d = r.diagonal[reference_index(x, y)];
    match half {
        Half::Lower => triplet(r.horizontal[reference_index(x, y)], r.vertical[reference_index(x + 1, y)], d),
        Half::Upper => triplet(r.horizontal[reference_index(x, y + 1)], r.vertical[reference_index(x, y)], d),
    }
}

/// The cell of the forest sample whose `half` has `triplet`, or `None` for a triplet that `half`
/// never has (a lower one of odd parity, an upper one of even).
pub fn sample_cell(half: Half, triplet: Triplet) -> Option<[u32; 2]> {
    (0..REFERENCE_CELLS)
        .flat_map(|y| (0..REFERENCE_CELLS).map(move |x| [x, y]))
        .find(|&[x, y]| reference_triplet(i64::from(x), i64::from(y), half) == triplet)
}

/// A lattice vertex's colour bit, from its position and the world's germ.
fn vertex_colour(i: i32, j: i32, seed: u32) -> u32 {
    pcg(pcg(pcg(i as u32 ^ 0x7e3c_a1f5) ^ (j as u32).wrapping_mul(0x9e37_79b9)) ^ seed) >> 31
}

/// The colour of the horizontal edge from vertex (`i`, `j`) to (`i` + 1, `j`).
pub fn horizontal_edge(i: i32, j: i32, seed: u32) -> u32 {
    vertex_colour(i, j, seed) ^ vertex_colour(i.wrapping_add(1), j, seed) ^ (j as u32 & 1)
}

/// The colour of the vertical edge from vertex (`i`, `j`) to (`i`, `j` + 1).
pub fn vertical_edge(i: i32, j: i32, seed: u32) -> u32 {
    vertex_colour(i, j, seed) ^ vertex_colour(i, j.wrapping_add(1), seed)
}

/// The triplet of the ground triangle `half` of cell `cell` in a world of germ `seed`.
pub fn ground_triplet(cell: [i32; 2], half: Half, seed: u32) -> Triplet {
    let [i, j] = cell;
    let (bottom, right) = (horizontal_edge(i, j, seed), vertical_edge(i.wrapping_add(1), j, seed));
    let diagonal = bottom ^ right;
    match half {
        Half::Lower => triplet(bottom, right, diagonal),
        Half::Upper => {
            triplet(horizontal_edge(i, j.wrapping_add(1), seed), vertical_edge(i, j, seed), diagonal)
        }
    }
}

/// The forest sample's cell that ground triangle `half` of `cell` shows.
pub fn ground_sample_cell(cell: [i32; 2], half: Half, seed: u32) -> [u32; 2] {
    // `ground_triplet` gives lower triangles even parity and upper ones odd, and the sample holds
    // every such triplet: the search cannot fail (`tests`).
    sample_cell(half, ground_triplet(cell, half, seed)).unwrap_or([0, 0])
}

/// Every (half, triplet)'s sample cell in one word, as the texcell shader looks them up: 2 bits
/// (x + 2y) at bit 2 · (8 · half + triplet), half 0 lower, 1 upper; triplets a half never has
/// read cell (0, 0).
pub fn sample_cells_word() -> u32 {
    let mut word = 0;
    for (h, half) in [Half::Lower, Half::Upper].into_iter().enumerate() {
        for t in 0..8 {
            let [x, y] = sample_cell(half, t).unwrap_or([0, 0]);
            word |= (x + REFERENCE_CELLS * y) << (2 * (8 * h as u32 + t));
        }
    }
    word
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parity(t: Triplet) -> u32 {
        (t ^ (t >> 1) ^ (t >> 2)) & 1
    }

    #[test]
    fn the_sample_holds_each_of_the_eight_tiles_once() {
        for half in [Half::Lower, Half::Upper] {
            let mut seen: Vec<Triplet> =
                (0..2).flat_map(|y| (0..2).map(move |x| reference_triplet(x, y, half))).collect();
            let want = if half == Half::Lower { 0 } else { 1 };
            assert!(seen.iter().all(|&t| parity(t) == want), "{half:?}: {seen:?}");
            seen.sort();
            seen.dedup();
            assert_eq!(seen.len(), 4, "{half:?}");
        }
        // Wrapping: the sample's neighbours across each edge agree on its colour, by construction
        // of the edge arrays (one colour per edge); a ground triangle's sample cell is found.
        for t in 0..8 {
            assert_eq!(sample_cell(Half::Lower, t).is_some(), parity(t) == 0);
            assert_eq!(sample_cell(Half::Upper, t).is_some(), parity(t) == 1);
        }
    }

    #[test]
    fn the_shader_word_names_each_tile_cell() {
        let word = sample_cells_word();
        for (h, half) in [Half::Lower, Half::Upper].into_iter().enumerate() {
            for t in 0..8 {
                let entry = (word >> (2 * (8 * h as u32 + t))) & 3;
                if let Some([x, y]) = sample_cell(half, t) {
                    assert_eq!(entry, x + 2 * y, "{half:?} {t}");
                }
            }
        }
    }

    #[test]
    fn neighbouring_ground_triangles_agree_on_every_shared_edge() {
        let seed = 7;
        let (mut lower_seen, mut upper_seen) = ([0u32; 8], [0u32; 8]);
        for j in -40..40 {
            for i in -40..40 {
                let lower = ground_triplet([i, j], Half::Lower, seed);
                let upper = ground_triplet([i, j], Half::Upper, seed);
                assert_eq!(parity(lower), 0, "lower ({i}, {j})");
                assert_eq!(parity(upper), 1, "upper ({i}, {j})");
                // The diagonal, inside the cell.
                assert_eq!(lower >> 2, upper >> 2);
                // The lower triangle's right side is the left side of the next cell's upper one.
                assert_eq!((lower >> 1) & 1, (ground_triplet([i + 1, j], Half::Upper, seed) >> 1) & 1);
                // The upper triangle's top is the bottom of the lower one of the cell above.
                assert_eq!(upper & 1, ground_triplet([i, j + 1], Half::Lower, seed) & 1);
                lower_seen[lower as usize] += 1;
                upper_seen[upper as usize] += 1;
            }
        }
        // Every tile is used, none overwhelmingly (6,400 of each half, four tiles each).
        for (t, (&l, &u)) in lower_seen.iter().zip(&upper_seen).enumerate() {
            let n = if parity(t as u32) == 0 { l } else { u };
            assert!((1100..=2100).contains(&n), "triplet {t}: {n} of 6400");
        }
        // Another germ, another tiling.
        let differs = (0..100)
            .filter(|&i| ground_triplet([i, 3], Half::Lower, 8) != ground_triplet([i, 3], Half::Lower, seed))
            .count();
        assert!(differs > 20, "{differs}");
    }
}
