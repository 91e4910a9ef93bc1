//! How it works: every plane of a LOD gets the same texel density (texels per metre), the largest
//! for which all its rectangles fit the atlas, found by bisection. A rectangle is the plane's
//! extent times that density plus one texel of margin per side, rounded up to a multiple of
//! `align` (2^(mips−1)), and rectangles are placed by shelf packing (tallest first, left to
//! right, a new shelf when a row is full) at multiples of `align` with `align` empty texels
//! between them: then no mip's 2 × 2 box mixes two planes, and the last mip still has a texel of
//! gap.

use crate::impostor::TexelRect;

/// Rectangles for planes of `extents_m` (width, height in metres), in their order.
#[derive(Debug, Clone, PartialEq)]
pub struct Packing {
    pub texels_per_m: f32,
    pub rects: Vec<TexelRect>,
}

fn round_up(value: u32, align: u32) -> u32 {
    value.div_ceil(align).max(1) * align
}

/// Shelf-packs `sizes` (texels) into a square of `atlas` texels, or `None` if they do not fit.
fn shelf(sizes: &[[u32; 2]], atlas: u32, align: u32) -> Option<Vec<TexelRect>> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(sizes[i][1]), std::cmp::Reverse(sizes[i][0]), i));
    let mut rects = vec![TexelRect { x: 0, y: 0, width: 0, height: 0 }; sizes.len()];
    let (mut x, mut y, mut shelf_height) = (0u32, 0u32, 0u32);
    for i in order {
        let [w, h] = sizes[i];
        if w > atlas || h > atlas {
            return None;
        }
        if x + w > atlas {
            (x, y, shelf_height) = (0, y + shelf_height + align, 0);
        }
        if y + h > atlas {
            return None;
        }
        rects[i] = TexelRect { x, y, width: w, height: h };
        x += w + align;
        shelf_height = shelf_height.max(h);
    }
    Some(rects)
}

/// The densest packing of `extents_m` into an `atlas` × `atlas` image, or `None` when even one
/// `align`-sized cell per plane does not fit.
pub fn pack(extents_m: &[[f32; 2]], atlas: u32, align: u32) -> Option<Packing> {
    let sizes_at = |density: f32| -> Vec<[u32; 2]> {
        extents_m.iter().map(|e| e.map(|m| round_up((m * density).ceil() as u32 + 2, align))).collect()
    };
    let largest = extents_m.iter().flatten().fold(1e-6f32, |a, &b| a.max(b));
    let (mut lo, mut hi) = (0.0f32, atlas as f32 / largest);
    let mut best = shelf(&sizes_at(lo), atlas, align)?;
    for _ in 0..32 {
        let mid = 0.5 * (lo + hi);
        match shelf(&sizes_at(mid), atlas, align) {
            Some(rects) => (lo, best) = (mid, rects),
            None => hi = mid,
        }
    }
    Some(Packing { texels_per_m: lo, rects: best })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangles_fit_apart_and_aligned_at_one_density() {
        let extents = [[4.0, 8.0], [4.0, 4.0], [1.0, 0.5], [6.0, 2.0], [0.0, 0.0]];
        let packing = pack(&extents, 256, 8).unwrap();
        assert!(packing.texels_per_m > 10.0, "{packing:?}");
        let rects = &packing.rects;
        for (i, r) in rects.iter().enumerate() {
            assert!(r.x % 8 == 0 && r.y % 8 == 0 && r.width % 8 == 0 && r.height % 8 == 0, "{r:?}");
            assert!(r.x + r.width <= 256 && r.y + r.height <= 256, "{r:?}");
            let needed = extents[i].map(|m| m * packing.texels_per_m + 2.0);
            assert!(r.width as f32 >= needed[0] && r.height as f32 >= needed[1], "{r:?}");
            for s in &rects[i + 1..] {
                let apart = r.x + r.width + 8 <= s.x
                    || s.x + s.width + 8 <= r.x
                    || r.y + r.height + 8 <= s.y
                    || s.y + s.height + 8 <= r.y;
                assert!(apart, "{r:?} {s:?}");
            }
        }
        assert!(pack(&[[1.0, 1.0]; 17], 32, 8).is_none());
    }
}
