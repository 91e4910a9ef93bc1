//! How it works: the geometry of a crown's slicings ([`super::Slicing`], Jakulin 2000) that the
//! baker and the drawing share: where each slicing faces ([`orientation`]), which two slicings a
//! view blends and how much of each ([`view_blend`]), and the order the paper draws their slices
//! in ([`interleaved_order`]).
//!
//! View blending, as the paper gives it: the eye's direction from the slicing centre, projected
//! onto the plane of the orientations (the horizontal: they all are), makes a discrepancy angle
//! with each orientation; the nearest is the primary, the next nearest the secondary. The
//! primary's opacity α_p falls linearly from 1 at a discrepancy of 0 to ½ where both
//! discrepancies are equal (half the angle between neighbouring orientations), α_s = 1 − α_p, and
//! both are multiplied by the brightness correction f_c = 1 + m_s α_s, which makes up for the
//! background the two half-opaque slicings let through.

use std::f32::consts::TAU;

use glam::Vec3;

/// The unit normal of slicing `i` of `orientations`, model space: horizontal, at azimuth
/// 2π i / orientations from +X towards +Z.
pub fn orientation(i: u32, orientations: u32) -> Vec3 {
    let azimuth = TAU * i as f32 / orientations as f32;
    Vec3::new(azimuth.cos(), 0.0, azimuth.sin())
}

/// The two slicings a view draws and their opacities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewBlend {
    /// The slicing whose orientation is nearest the eye's direction.
    pub primary: u32,
    /// The next nearest.
    pub secondary: u32,
    /// The primary's opacity, brightness correction included: from 1 (the eye on its
    /// orientation) down to (1 + m_s / 2) / 2 (the eye half-way to the secondary's).
    pub alpha_primary: f32,
    /// The secondary's, brightness correction included: from 0 up to the primary's.
    pub alpha_secondary: f32,
    /// Whether the primary is the one of the two at the lower azimuth (the secondary the next
    /// orientation). A stochastic blend gives the lower one the dither's low thresholds and the
    /// other the high ones, so each slicing keeps its pixels when the two trade roles half-way.
    pub primary_lower: bool,
}

/// The blend of `orientations` slicings for an eye along `eye_model` from the slicing centre
/// (model space, any length), with the brightness correction's multiplier `correction` (m_s,
/// the paper's 0.5). An eye straight above or below sees slicing 0 alone.
pub fn view_blend(eye_model: Vec3, orientations: u32, correction: f32) -> ViewBlend {
    let n = orientations.max(1);
    let step = TAU / n as f32;
    // Azimuth from +X towards +Z, as `orientation` counts it, in [0, 2π).
    let azimuth = eye_model.z.atan2(eye_model.x).rem_euclid(TAU);
    let nearest = (azimuth / step).round();
    let primary = (nearest as u32) % n;
    // Signed discrepancy from the primary, at most half a step either way.
    let discrepancy = azimuth - nearest * step;
    let secondary = if n == 1 {
        0
    } else if discrepancy >= 0.0 {
        (primary + 1) % n
    } else {
        (primary + n - 1) % n
    };
    let alpha_primary = if n == 1 { 1.0 } else { 1.0 - discrepancy.abs() / step };
    let alpha_secondary = 1.0 - alpha_primary;
    let brightness = 1.0 + correction * alpha_secondary;
    ViewBlend {
        primary,
        secondary,
        alpha_primary: brightness * alpha_primary,
        alpha_secondary: brightness * alpha_secondary,
        primary_lower: discrepancy >= 0.0,
    }
}

/// The paper's drawing order of a blend's slices, `(slicing, slice)`, for an eye along
/// `eye_model`: the farthest secondary slice, the farthest primary slice, the second farthest
/// secondary slice, and so on to the nearest primary one. Slice j of a slicing lies j spacings
/// along its orientation from its first, so the farthest slice of a slicing facing the eye is its
/// first.
pub fn interleaved_order(
    blend: &ViewBlend,
    slices: u32,
    eye_model: Vec3,
    orientations: u32,
) -> Vec<(u32, u32)> {
    let far_to_near = |slicing: u32| -> Vec<u32> {
        if orientation(slicing, orientations).dot(eye_model) >= 0.0 {
            (0..slices).collect()
        } else {
            (0..slices).rev().collect()
        }
    };
    let (secondary, primary) = (far_to_near(blend.secondary), far_to_near(blend.primary));
    secondary.into_iter().zip(primary).flat_map(|(s, p)| [(blend.secondary, s), (blend.primary, p)]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIX: u32 = 6;

    /// The eye at azimuth `degrees` (from +X towards +Z), a little above the horizon.
    fn eye(degrees: f32) -> Vec3 {
        let a = degrees.to_radians();
        Vec3::new(a.cos(), 0.3, a.sin())
    }

    #[test]
    fn orientations_are_evenly_spread_around_the_vertical() {
        for n in [1, 4, 6] {
            let normals: Vec<Vec3> = (0..n).map(|i| orientation(i, n)).collect();
            assert!(normals.iter().all(|v| v.y == 0.0 && (v.length() - 1.0).abs() < 1e-6));
            for i in 0..n as usize {
                let next = normals[(i + 1) % n as usize];
                let angle = normals[i].angle_between(next);
                let expected = if n == 1 { 0.0 } else { TAU / n as f32 };
                assert!((angle - expected.min(TAU - expected)).abs() < 1e-5, "{n}: {angle}");
            }
        }
    }

    #[test]
    fn an_eye_on_an_orientation_sees_that_slicing_alone() {
        for i in 0..SIX {
            let b = view_blend(eye(60.0 * i as f32), SIX, 0.5);
            assert_eq!(b.primary, i);
            assert!((b.alpha_primary - 1.0).abs() < 1e-5 && b.alpha_secondary.abs() < 1e-5, "{b:?}");
        }
    }

    #[test]
    fn half_way_between_two_orientations_both_are_equal_and_brightened() {
        let b = view_blend(eye(30.0 + 1e-3), SIX, 0.5);
        assert_eq!((b.primary, b.secondary, b.primary_lower), (1, 0, false));
        // α_p = α_s = ½, each times f_c = 1 + 0.5 · ½.
        assert!((b.alpha_primary - 0.625).abs() < 1e-4 && (b.alpha_secondary - 0.625).abs() < 1e-4, "{b:?}");
        let plain = view_blend(eye(30.0 - 1e-3), SIX, 0.0);
        assert_eq!((plain.primary, plain.secondary, plain.primary_lower), (0, 1, true));
        assert!((plain.alpha_primary - 0.5).abs() < 1e-4 && (plain.alpha_secondary - 0.5).abs() < 1e-4);
    }

    #[test]
    fn the_primary_fades_linearly_towards_the_secondary() {
        // A sixth of the way from orientation 5 (300°) towards 0 (360°): 10° of a 60° step.
        let b = view_blend(eye(310.0), SIX, 0.0);
        assert_eq!((b.primary, b.secondary), (5, 0));
        assert!((b.alpha_primary - (1.0 - 10.0 / 60.0)).abs() < 1e-5, "{b:?}");
        assert!((b.alpha_primary + b.alpha_secondary - 1.0).abs() < 1e-6);
        // Across 0° the neighbours swap sides.
        let b = view_blend(eye(-10.0), SIX, 0.0);
        assert_eq!((b.primary, b.secondary), (0, 5));
        // Height does not matter: the eye is projected onto the orientations' plane.
        assert_eq!(
            view_blend(eye(47.0) * Vec3::new(1.0, 9.0, 1.0), SIX, 0.5),
            view_blend(eye(47.0), SIX, 0.5)
        );
    }

    #[test]
    fn slices_are_drawn_secondary_then_primary_from_the_farthest() {
        let at = eye(20.0);
        let b = view_blend(at, SIX, 0.5);
        assert_eq!((b.primary, b.secondary), (0, 1));
        let order = interleaved_order(&b, 3, at, SIX);
        assert_eq!(order, [(1, 0), (0, 0), (1, 1), (0, 1), (1, 2), (0, 2)]);
        // With two slicings the secondary can face away from the eye: its last slice is then the
        // farthest.
        let two = view_blend(eye(80.0), 2, 0.5);
        assert_eq!((two.primary, two.secondary), (0, 1));
        assert_eq!(interleaved_order(&two, 2, eye(80.0), 2), [(1, 1), (0, 0), (1, 0), (0, 1)]);
    }
}
