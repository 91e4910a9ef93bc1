//! How it works: what the slicings' stochastic blend (pass 4's `slice_blend`, `faded_out`) costs
//! against the paper's sorted blending, on one impostor seen from one direction, on the CPU. Both
//! images are orthographic views of the crown's slices along the eye's direction, a pixel per
//! ray, each slice sampled where the ray crosses it (the atlas's nearest texel of mip 0, opaque
//! at the impostor's cutoff):
//! - **sorted** (the reference): the slices of the primary and secondary slicings composited back
//!   to front in the paper's interleaved order (`interleaved_order`), each opaque texel with its
//!   slicing's corrected opacity, over the background;
//! - **stochastic** (what pass 4 draws): the nearest opaque texel of a slicing that keeps the
//!   pixel by the blend's ordered dither (`bayer4` transposed, [0, α̅) for the slicing at the
//!   lower azimuth, [1 − α̅, 1) for the other), as depth testing leaves it, else the background.
//!
//! The eye integrates the dither over its 4 × 4 pattern, so both are box-filtered over 4 × 4
//! pixels before they are compared: the mean absolute difference per channel, 0 to 255, over
//! the blocks either image draws the crown in.

use glam::Vec3;

use crate::gpu::layout::SLICE_DITHER_SALT;
use crate::impostor::slicing::{interleaved_order, view_blend};
use crate::impostor::{Impostor, Plane};

/// Pixels along the views' side (a multiple of 4).
pub const VIEW_PX: usize = 128;

/// The two images and their difference.
#[derive(Debug, Clone, PartialEq)]
pub struct BlendError {
    /// Mean absolute difference per channel of the 4 × 4 block means, levels of 255, over the
    /// blocks either image covers.
    pub mean_abs: f64,
    /// Blocks either image covers.
    pub blocks: usize,
    /// The share of the crown's opacity the stochastic image keeps, over the sorted one's (1 alike).
    pub coverage_ratio: f64,
}

/// The ordered dither of `shaders/shared/dither.wgsl`'s `bayer4`, its twin.
pub fn bayer4(pixel: [u32; 2], shift: u32) -> f32 {
    const M: [u32; 16] = [0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5];
    let (x, y) = (pixel[0] + (shift & 3), pixel[1] + (shift >> 2));
    (M[((y & 3) * 4 + (x & 3)) as usize] as f32 + 0.5) / 16.0
}

/// Where a ray from `origin` along `dir` crosses `plane`, and the atlas texel there (RGBA), if
/// it crosses inside the slice: (distance along the ray, texel).
fn hit(impostor: &Impostor, plane: &Plane, origin: Vec3, dir: Vec3) -> Option<(f32, [u8; 4])> {
    let atlas = &impostor.slicing.as_ref()?.lod.atlas;
    let c = plane.corners_model_m.map(Vec3::from);
    let normal = Vec3::from(plane.normal_model);
    let facing = dir.dot(normal);
    if facing.abs() < 1e-6 {
        return None;
    }
    let t = (c[0] - origin).dot(normal) / facing;
    let p = origin + dir * t;
    let (right, up) = (c[1] - c[0], c[3] - c[0]);
    let (s, v) = ((p - c[0]).dot(right) / right.length_squared(), (p - c[0]).dot(up) / up.length_squared());
    if !(0.0..1.0).contains(&s) || !(0.0..1.0).contains(&v) {
        return None;
    }
    let [w, h] = atlas.size;
    let u = plane.uv_min[0] + s * (plane.uv_max[0] - plane.uv_min[0]);
    let y = plane.uv_max[1] - v * (plane.uv_max[1] - plane.uv_min[1]);
    let (x, y) =
        (((u * w as f32) as usize).min(w as usize - 1), ((y * h as f32) as usize).min(h as usize - 1));
    let i = 4 * (y * w as usize + x);
    let texel = &atlas.levels[0][i..i + 4];
    Some((t, [texel[0], texel[1], texel[2], texel[3]]))
}

/// The two pictures of a slicing's blend, `VIEW_PX`² each, top row first: premultiplied colour
/// (sRGB levels, 0 to 255) and opacity (0 to 1), over nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct BlendViews {
    /// The paper's: slices composited back to front at their slicings' opacities.
    pub sorted: Vec<[f32; 4]>,
    /// Pass 4's: the nearest opaque texel of a slicing the dither gives the pixel.
    pub stochastic: Vec<[f32; 4]>,
}

/// The stochastic blend's error against the sorted one for `impostor`'s slicing seen from
/// `eye_model` (a direction from the crown's middle, model space), with the brightness
/// correction's multiplier `correction` and the dither's shift `shift` (a seed's rank);
/// `None` without a slicing.
pub fn blend_error(impostor: &Impostor, eye_model: Vec3, correction: f32, shift: u32) -> Option<BlendError> {
    let views = blend_views(impostor, eye_model, correction, shift)?;
    Some(compare_blocks(&views.sorted, &views.stochastic))
}

/// Both pictures of `impostor`'s slicing seen from `eye_model`, as [`blend_error`] compares them.
pub fn blend_views(impostor: &Impostor, eye_model: Vec3, correction: f32, shift: u32) -> Option<BlendViews> {
    let slicing = impostor.slicing.as_ref()?;
    let (n, slices) = (slicing.orientations, slicing.slices);
    let blend = view_blend(eye_model, n, correction);
    let eye = eye_model.normalize();
    let sphere = &impostor.bounding_sphere;
    let centre = Vec3::from(sphere.centre_model_m);
    let side = if eye.y.abs() > 0.99 { Vec3::X } else { Vec3::Y.cross(eye).normalize() };
    let up = eye.cross(side);
    let cutoff = (impostor.alpha_cutoff * 255.0) as u8;
    let plane =
        |slicing_index: u32, slice: u32| &slicing.lod.planes[(slicing_index * slices + slice) as usize];
    let order = interleaved_order(&blend, slices, eye_model, n);
    let background = [0.0f32; 4];
    let (mut sorted, mut stochastic) =
        (vec![background; VIEW_PX * VIEW_PX], vec![background; VIEW_PX * VIEW_PX]);
    for py in 0..VIEW_PX {
        for px in 0..VIEW_PX {
            let (fx, fy) = [px, py].map(|k| (k as f32 + 0.5) / VIEW_PX as f32 * 2.0 - 1.0).into();
            let origin = centre + eye * 4.0 * sphere.radius_m + (side * fx - up * fy) * sphere.radius_m;
            let dir = -eye;
            let pixel = py * VIEW_PX + px;
            // Sorted: back to front in the paper's order, each opaque texel at its opacity.
            let mut colour = background;
            for &(s, j) in &order {
                let Some((_, texel)) = hit(impostor, plane(s, j), origin, dir) else { continue };
                if texel[3] < cutoff {
                    continue;
                }
                let alpha =
                    if s == blend.primary { blend.alpha_primary } else { blend.alpha_secondary }.min(1.0);
                for k in 0..3 {
                    colour[k] = f32::from(texel[k]) * alpha + colour[k] * (1.0 - alpha);
                }
                colour[3] = alpha + colour[3] * (1.0 - alpha);
            }
            sorted[pixel] = colour;
            // Stochastic: the nearest opaque texel of a slicing the dither gives the pixel.
            let b = bayer4([py as u32, px as u32], shift ^ SLICE_DITHER_SALT);
            // The lower of the two slicings keeps the low thresholds, the other the high ones.
            let keeps = |s: u32| {
                let alpha = if s == blend.primary { blend.alpha_primary } else { blend.alpha_secondary };
                if (s == blend.primary) == blend.primary_lower { b < alpha } else { b >= 1.0 - alpha }
            };
            let nearest = order
                .iter()
                .filter(|(s, _)| keeps(*s))
                .filter_map(|&(s, j)| hit(impostor, plane(s, j), origin, dir))
                .filter(|(_, texel)| texel[3] >= cutoff)
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, texel)) = nearest {
                stochastic[pixel] = [f32::from(texel[0]), f32::from(texel[1]), f32::from(texel[2]), 1.0];
            }
        }
    }
    Some(BlendViews { sorted, stochastic })
}

/// The 4 × 4 block means of two images compared: mean absolute difference per channel over the
/// blocks either covers, and their coverage ratio.
fn compare_blocks(sorted: &[[f32; 4]], stochastic: &[[f32; 4]]) -> BlendError {
    let blocks = VIEW_PX / 4;
    let (mut sum, mut covered, mut cover_sorted, mut cover_stochastic) = (0.0f64, 0usize, 0.0f64, 0.0f64);
    for by in 0..blocks {
        for bx in 0..blocks {
            let mean = |image: &[[f32; 4]]| {
                let mut m = [0.0f64; 4];
                for y in 0..4 {
                    for x in 0..4 {
                        let p = image[(4 * by + y) * VIEW_PX + 4 * bx + x];
                        for k in 0..4 {
                            m[k] += f64::from(p[k]) / 16.0;
                        }
                    }
                }
                m
            };
            let (a, b) = (mean(sorted), mean(stochastic));
            cover_sorted += a[3];
            cover_stochastic += b[3];
            if a[3] > 0.0 || b[3] > 0.0 {
                covered += 1;
                sum += (0..3).map(|k| (a[k] - b[k]).abs()).sum::<f64>() / 3.0;
            }
        }
    }
    BlendError {
        mean_abs: if covered > 0 { sum / covered as f64 } else { 0.0 },
        blocks: covered,
        coverage_ratio: if cover_sorted > 0.0 { cover_stochastic / cover_sorted } else { 1.0 },
    }
}
