//! How it works: the ground as the terrain mesh draws it, defined once on the CPU (its WGSL twin
//! is `shaders/shared/terrain_surface.wgsl`). The mesh (`passes::terrain`) is a grid whose
//! vertices are a height level's samples, each cell split into two triangles along a diagonal that
//! alternates like a checkerboard (`diagonal_rises`, the one rule the mesh's index buffer, pass 3
//! and the oracle all follow). So the drawn ground is piecewise planar: in a cell, the plane of the
//! triangle holding the point. At level 0, where the finest mesh is drawn unmorphed, it is exactly
//! the surface on screen; a seed placed on it stands on what is drawn, where the bilinear patch
//! through the same four samples could float up to a quarter of the cell's twist above it.
//!
//! A triangle is named by its right-angle corner `c`, the cell corner whose two cell edges it
//! keeps: height = h(c) + sx·(u − cx) + sy·(v − cy), with its slopes per cell
//! sx = h(1, cy) − h(0, cy) and sy = h(cx, 1) − h(cx, 0). `drawn_height` takes these steps in the
//! WGSL twin's order, generic over f32 (the CPU twin of pass 3, bit for bit) and f64 (the oracle,
//! `Dataset::height_at`).

use std::ops::{Add, Mul, Sub};

/// The arithmetic `drawn_height` needs: f32 and f64.
pub trait Scalar:
    Copy + PartialOrd + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + From<u8>
{
}

impl<T> Scalar for T where
    T: Copy + PartialOrd + Add<Output = T> + Sub<Output = T> + Mul<Output = T> + From<u8>
{
}

/// Whether the terrain mesh splits cell (`i`, `j`) of a height level (the cell whose south-west
/// corner is sample (`i`, `j`)) along its rising diagonal, south-west to north-east; otherwise
/// along its falling one, south-east to north-west. Alternating like a checkerboard, so the
/// triangulation has no directional bias (a slope facing any way is cut as often both ways).
pub fn diagonal_rises([i, j]: [u32; 2]) -> bool {
    (i ^ j) & 1 == 0
}

/// The right-angle corner (0 or 1 per axis: west/east, south/north) of the triangle of `cell`
/// that holds position `f` in it (cells, [0, 1]²). On the diagonal either triangle is right:
/// both give the same height.
pub fn triangle_corner<T: Scalar>(cell: [u32; 2], [u, v]: [T; 2]) -> [u32; 2] {
    if diagonal_rises(cell) {
        if u >= v { [1, 0] } else { [0, 1] }
    } else if u + v > T::from(1) {
        [1, 1]
    } else {
        [0, 0]
    }
}

/// Height of the drawn ground at position `f` in `cell` (cells, [0, 1]²), whose corners' heights
/// are `corners` (south-west, south-east, north-west, north-east), and its slope there (height
/// change per cell east and north).
pub fn drawn_height<T: Scalar>(cell: [u32; 2], corners: [T; 4], f: [T; 2]) -> (T, [T; 2]) {
    let [cx, cy] = triangle_corner(cell, f);
    let h = |x: u32, y: u32| corners[(y * 2 + x) as usize];
    let slope = [h(1, cy) - h(0, cy), h(cx, 1) - h(cx, 0)];
    // f − c is exact where c is 0; where it is 1 the triangle's own corner is nearer.
    let offset = [f[0] - T::from(cx as u8), f[1] - T::from(cy as u8)];
    (h(cx, cy) + slope[0] * offset[0] + slope[1] * offset[1], slope)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plane through three (x, y, z) points, at (x, y): barycentric, the obvious way.
    fn plane(p: [[f64; 3]; 3], x: f64, y: f64) -> f64 {
        let [a, b, c] = p;
        let det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
        let wa = ((b[1] - c[1]) * (x - c[0]) + (c[0] - b[0]) * (y - c[1])) / det;
        let wb = ((c[1] - a[1]) * (x - c[0]) + (a[0] - c[0]) * (y - c[1])) / det;
        wa * a[2] + wb * b[2] + (1.0 - wa - wb) * c[2]
    }

    #[test]
    fn each_triangle_is_the_plane_of_its_three_corners_and_the_surface_is_continuous() {
        let corners = [3.0, -1.5, 7.25, 0.5];
        let at = |x: f64, y: f64| [x, y, corners[(y as usize) * 2 + x as usize]];
        for cell in [[0u32, 0], [1, 0], [4, 7], [7, 7]] {
            // The rising diagonal joins south-west and north-east, the falling one the other two.
            let (lower, upper) = if diagonal_rises(cell) {
                ([at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0)], [at(0.0, 0.0), at(1.0, 1.0), at(0.0, 1.0)])
            } else {
                ([at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0)], [at(1.0, 0.0), at(1.0, 1.0), at(0.0, 1.0)])
            };
            for k in 0..=20 {
                for l in 0..=20 {
                    let (u, v) = (f64::from(k) / 20.0, f64::from(l) / 20.0);
                    let below = if diagonal_rises(cell) { u >= v } else { u + v <= 1.0 };
                    let want = plane(if below { lower } else { upper }, u, v);
                    let (got, slope) = drawn_height(cell, corners, [u, v]);
                    assert!((got - want).abs() < 1e-12, "{cell:?} ({u}, {v}): {got} against {want}");
                    let e = 1e-7;
                    let (east, _) = drawn_height(cell, corners, [u + e, v]);
                    let (north, _) = drawn_height(cell, corners, [u, v + e]);
                    // Away from the diagonal the slope is the surface's own; everywhere it is continuous.
                    let on_diagonal =
                        if diagonal_rises(cell) { (u - v).abs() < 1e-6 } else { (u + v - 1.0).abs() < 1e-6 };
                    if !on_diagonal && k < 20 && l < 20 {
                        assert!(
                            ((east - got) / e - slope[0]).abs() < 1e-5
                                && ((north - got) / e - slope[1]).abs() < 1e-5
                        );
                    }
                    assert!((east - got).abs() < 1e-5 && (north - got).abs() < 1e-5);
                }
            }
        }
        // Neighbouring cells alternate.
        assert!(
            diagonal_rises([0, 0])
                && !diagonal_rises([1, 0])
                && !diagonal_rises([0, 1])
                && diagonal_rises([1, 1])
        );
    }

    #[test]
    fn f32_and_f64_take_the_same_triangle_and_agree() {
        let corners = [1024.5f32, 1030.25, 1019.0, 1041.75];
        for (cell, f) in [([2u32, 3], [0.25f32, 0.75]), ([3, 3], [0.6, 0.3]), ([8, 1], [0.999, 0.0])] {
            let (h32, _) = drawn_height(cell, corners, f);
            let (h64, _) = drawn_height(cell, corners.map(f64::from), f.map(f64::from));
            assert_eq!(triangle_corner(cell, f), triangle_corner(cell, f.map(f64::from)));
            assert!((f64::from(h32) - h64).abs() < 1e-3, "{cell:?}: {h32} against {h64}");
        }
    }
}
