//! How it works: the continuous level of detail of generated trees (Wesslén & Seipel § 3). A mesh
//! whose materials say how their primitives shrink ([`Detail`]) is drawn whole up close and sheds
//! detail gradually with distance, by index ranges in buffers the tree generator prearranged: its
//! leaves are quads sorted by the uniform that decided their survival, so any run of them is a
//! uniform thinning of the crown; its stems are one material per branching level, trunk first.
//!
//! The rule is stochastic simplification (Cook, Halstead, Planck & Ryu 2007): what shrinks below
//! a size is drawn at that size, for a share of it equal to the square (leaves, areas) or the
//! ratio (stems, widths) of its size over that, so that what the view covers stays what it was,
//! on average, and nothing drawn is smaller. Leaves below `DETAIL_FULL_PX` keep their last share
//! in buffer order, each grown about the point it hangs from back to `DETAIL_FULL_PX`; stems
//! narrower than `DETAIL_MIN_PX` are widened along their normals to it, each stem on a share of
//! the seeds (hashed from the seed and the stem's base, which the generator writes as its
//! vertices' pivot). The paper turns such leaves and twigs into points and lines,
//! which are one pixel whatever they stand for: a trunk a third of a pixel wide would be drawn
//! three times too heavy, or (removed below one pixel, the paper's last step) not at all, where
//! the ground truth shows a faint line; here it is a full line on a third of the trees, and a
//! third of a crown's thin branches on each tree. The shader
//! (`draw_seeds.wgsl`, `detail_position`) decides this per seed and vertex with the same
//! expressions as [`leaf_share`], [`leaf_kept`] and [`stem_share`]; the CPU narrows each draw's
//! index range to the leaves its nearest possible seed keeps (`passes::draw_seeds::frame`), so
//! thinned leaves cost no vertex work either.

use serde::{Deserialize, Serialize};

use crate::gpu::layout::{DETAIL_FULL_PX, DETAIL_MIN_PX};

/// How a material's primitives leave the mesh as they shrink on screen. The tree generator writes
/// it in each material's glTF `extras` (`DETAIL_EXTRAS`); other models have none and are drawn
/// whole.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Detail {
    /// Leaf quads, four vertices and two triangles each, in the order they thin out: the first
    /// go first.
    Leaves {
        /// The leaves' mean size (the side of a square of a leaf's area), model metres.
        size_m: f32,
    },
    /// The stems of one branching level.
    Stems {
        /// Their mean diameter, model metres.
        diameter_m: f32,
    },
}

/// The key of a glTF material's `extras` object that holds its [`Detail`].
pub const DETAIL_EXTRAS: &str = "terramp_detail";

/// Pixels that `size_m` (model metres) covers on a seed drawn at `scale` times the model's size,
/// `distance_m` away, through a lens of focal length `focal_px` (pixels).
pub fn projected_px(size_m: f32, scale: f32, focal_px: f32, distance_m: f32) -> f32 {
    size_m * scale * focal_px / distance_m.max(1e-3)
}

/// The share of a crown's leaves drawn when a leaf projects to `size_px`, and how much each drawn
/// leaf grows: all of them at their size from `DETAIL_FULL_PX` up; below it the square of the
/// ratio, grown back to `DETAIL_FULL_PX`.
pub fn leaf_share(size_px: f32) -> (f32, f32) {
    // (Written so that a NaN size keeps nothing.)
    let ratio = if size_px > 0.0 { (size_px / DETAIL_FULL_PX).min(1.0) } else { 0.0 };
    if ratio >= 1.0 {
        return (1.0, 1.0);
    }
    (ratio * ratio, 1.0 / ratio.max(1e-6))
}

/// Whether leaf `leaf` of `count` is drawn when `share` of them are: the last ones in buffer
/// order (the shader's test, in the same f32 steps).
pub fn leaf_kept(leaf: u32, count: u32, share: f32) -> bool {
    (count.saturating_sub(leaf)) as f32 - 0.5 < share * count as f32
}

/// The first leaf of `count` that [`leaf_kept`] draws at `share` (`count`: none).
pub fn first_leaf_kept(count: u32, share: f32) -> u32 {
    let guess = (count as f32 * (1.0 - share) - 0.5).floor().clamp(0.0, count as f32) as u32;
    let mut leaf = guess;
    while leaf > 0 && leaf_kept(leaf - 1, count, share) {
        leaf -= 1;
    }
    while leaf < count && !leaf_kept(leaf, count, share) {
        leaf += 1;
    }
    leaf
}

/// The share of the seeds that draw stems `diameter_px` across on screen, and how wide, pixels,
/// they are drawn: all of them as they are from `DETAIL_MIN_PX` up; below it the ratio, widened to
/// `DETAIL_MIN_PX`.
pub fn stem_share(diameter_px: f32) -> (f32, f32) {
    if diameter_px >= DETAIL_MIN_PX {
        return (1.0, diameter_px);
    }
    // (Written so that a NaN size keeps nothing.)
    let share = if diameter_px > 0.0 { diameter_px / DETAIL_MIN_PX } else { 0.0 };
    (share, DETAIL_MIN_PX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_thin_by_the_square_of_their_size_and_grow_back_to_full_size() {
        assert_eq!(leaf_share(DETAIL_FULL_PX * 3.0), (1.0, 1.0));
        let (share, grow) = leaf_share(0.5 * DETAIL_FULL_PX);
        assert_eq!((share, grow), (0.25, 2.0));
        // Drawn leaves are DETAIL_FULL_PX across, and the crown keeps its area.
        for size_px in [0.01, 0.3, 1.0, 1.7] {
            let (share, grow) = leaf_share(size_px);
            assert!((size_px * grow - DETAIL_FULL_PX).abs() < 1e-4);
            assert!((share * (size_px * grow).powi(2) - size_px * size_px).abs() < 1e-4);
        }
        assert_eq!(leaf_share(0.0).0, 0.0);
        assert_eq!(leaf_share(f32::NAN).0, 0.0, "a NaN size draws nothing");
    }

    #[test]
    fn the_kept_leaves_are_the_last_run_and_the_first_one_is_found_exactly() {
        for count in [0, 1, 7, 1000, 4099] {
            for share in [0.0, 1e-4, 0.013, 0.25, 0.5, 0.999, 1.0] {
                let first = first_leaf_kept(count, share);
                assert!((0..count).all(|i| leaf_kept(i, count, share) == (i >= first)), "{count} {share}");
                let kept = count - first;
                assert!((kept as f32 - share * count as f32).abs() <= 1.0, "{count} {share}: {kept} kept");
            }
        }
    }

    #[test]
    fn thin_stems_are_widened_to_a_pixel_on_a_share_of_the_seeds() {
        assert_eq!(stem_share(3.0 * DETAIL_MIN_PX), (1.0, 3.0 * DETAIL_MIN_PX));
        let (share, width_px) = stem_share(projected_px(0.02, 1.0, 600.0, 48.0));
        assert!((share - 0.25 / DETAIL_MIN_PX).abs() < 1e-6 && width_px == DETAIL_MIN_PX);
        // The expected width drawn is the stem's own.
        for diameter_px in [0.01, 0.2, 0.9] {
            let (share, width_px) = stem_share(diameter_px);
            assert!((share * width_px - diameter_px).abs() < 1e-6);
        }
        assert_eq!(stem_share(f32::NAN).0, 0.0, "a NaN size draws nothing");
    }
}
