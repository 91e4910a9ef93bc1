//! How it works: a model, on the CPU, of what pass 4 draws of a crown's slicings (`slice_blend`,
//! `faded_out`), and what its stochastic blend costs against the paper's sorted blending. A
//! [`SlicingView`] is one eye's blend; along any ray through the crown it gives, each slice
//! sampled where the ray crosses it (the atlas's nearest texel of mip 0, opaque at the
//! impostor's cutoff):
//! - **sorted** (the reference): the slices of the primary and secondary slicings composited back
//!   to front in the paper's interleaved order (`interleaved_order`), each opaque texel with its
//!   slicing's corrected opacity, over the background;
//! - **stochastic** (what pass 4 draws): the nearest opaque texel of a slicing that keeps the
//!   ray's screen pixel by the blend's ordered dither (`bayer4` transposed, [0, α̅) for the
//!   slicing at the lower azimuth, [1 − α̅, 1) for the other), as depth testing leaves it;
//! - and the trunk and limbs, the mesh's bark triangles that LOD 1 draws beside the slices.
//!
//! `blend_views` makes both pictures of an orthographic view along the eye's direction, a pixel
//! per ray. The eye integrates the dither over its 4 × 4 pattern, so both are box-filtered over
//! 4 × 4 pixels before they are compared (`BlendError`): the mean absolute difference per channel,
//! 0 to 255, over the blocks either image draws the crown in. `tests/slicings_views.rs` holds the
//! model to pass 4's frames, ray by pixel of a perspective view.

use glam::Vec3;

use crate::gpu::layout::SLICE_DITHER_SALT;
use crate::impostor::slicing::{ViewBlend, interleaved_order, view_blend};
use crate::impostor::{Impostor, MipChain, Plane, Slicing};

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
fn hit(atlas: &MipChain, plane: &Plane, origin: Vec3, dir: Vec3) -> Option<(f32, [u8; 4])> {
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

/// Both pictures of `impostor`'s slicing seen from `eye_model` (a direction from the crown's
/// middle, model space), with the brightness correction's multiplier `correction` and the
/// dither's shift `shift` (a seed's rank), as [`BlendError::between`] compares them; `None`
/// without a slicing.
pub fn blend_views(impostor: &Impostor, eye_model: Vec3, correction: f32, shift: u32) -> Option<BlendViews> {
    let view = SlicingView::new(impostor, eye_model, correction)?;
    let eye = eye_model.normalize();
    let sphere = &impostor.bounding_sphere;
    let centre = Vec3::from(sphere.centre_model_m);
    let side = if eye.y.abs() > 0.99 { Vec3::X } else { Vec3::Y.cross(eye).normalize() };
    let up = eye.cross(side);
    let background = [0.0f32; 4];
    let (mut sorted, mut stochastic) =
        (vec![background; VIEW_PX * VIEW_PX], vec![background; VIEW_PX * VIEW_PX]);
    for py in 0..VIEW_PX {
        for px in 0..VIEW_PX {
            let (fx, fy) = [px, py].map(|k| (k as f32 + 0.5) / VIEW_PX as f32 * 2.0 - 1.0).into();
            let origin = centre + eye * 4.0 * sphere.radius_m + (side * fx - up * fy) * sphere.radius_m;
            let pixel = py * VIEW_PX + px;
            sorted[pixel] = view.sorted(origin, -eye);
            if let Some((_, texel)) = view.stochastic(origin, -eye, [px as u32, py as u32], shift) {
                stochastic[pixel] = [f32::from(texel[0]), f32::from(texel[1]), f32::from(texel[2]), 1.0];
            }
        }
    }
    Some(BlendViews { sorted, stochastic })
}

/// One view of an impostor's slicings: the two slicings its eye blends, and what either blend
/// draws along any ray through the crown (model space: `origin` a point, `dir` a unit direction).
/// Built once per eye; pass 4 takes the eye from the crown's middle for every pixel of a seed.
#[derive(Debug, Clone)]
pub struct SlicingView<'a> {
    impostor: &'a Impostor,
    slicing: &'a Slicing,
    blend: ViewBlend,
    /// The paper's drawing order of the two slicings' slices, `(slicing, slice)`.
    order: Vec<(u32, u32)>,
    /// The alpha test, in atlas levels.
    cutoff: u8,
}

impl<'a> SlicingView<'a> {
    /// The view of `impostor`'s slicings from `eye_model` (a direction from the crown's middle,
    /// model space) with the brightness correction's multiplier `correction`; `None` without a
    /// slicing.
    pub fn new(impostor: &'a Impostor, eye_model: Vec3, correction: f32) -> Option<Self> {
        let slicing = impostor.slicing.as_ref()?;
        let blend = view_blend(eye_model, slicing.orientations, correction);
        let order = interleaved_order(&blend, slicing.slices, eye_model, slicing.orientations);
        Some(Self { impostor, slicing, blend, order, cutoff: (impostor.alpha_cutoff * 255.0) as u8 })
    }

    /// Where the ray crosses slice `slice` of slicing `slicing`, and the opaque texel there, if any.
    fn opaque_hit(&self, slicing: u32, slice: u32, origin: Vec3, dir: Vec3) -> Option<(f32, [u8; 4])> {
        let plane = &self.slicing.lod.planes[(slicing * self.slicing.slices + slice) as usize];
        hit(&self.slicing.lod.atlas, plane, origin, dir).filter(|(_, texel)| texel[3] >= self.cutoff)
    }

    /// The paper's sorted blend along the ray: the slices back to front in the paper's order,
    /// each opaque texel at its slicing's corrected opacity (at most 1), over nothing:
    /// premultiplied colour (sRGB levels, 0 to 255) and opacity (0 to 1).
    pub fn sorted(&self, origin: Vec3, dir: Vec3) -> [f32; 4] {
        let mut colour = [0.0f32; 4];
        for &(s, j) in &self.order {
            let Some((_, texel)) = self.opaque_hit(s, j, origin, dir) else { continue };
            let b = &self.blend;
            let alpha = if s == b.primary { b.alpha_primary } else { b.alpha_secondary }.min(1.0);
            for k in 0..3 {
                colour[k] = f32::from(texel[k]) * alpha + colour[k] * (1.0 - alpha);
            }
            colour[3] = alpha + colour[3] * (1.0 - alpha);
        }
        colour
    }

    /// Pass 4's stochastic blend along the ray through screen pixel `pixel` (x, y) of a seed
    /// whose dither is shifted by `shift` (its rank): the nearest opaque texel of a slicing that
    /// keeps the pixel by the blend's ordered dither (`bayer4` transposed, [0, α̅) for the slicing
    /// at the lower azimuth, [1 − α̅, 1) for the other), as depth testing leaves it: its distance
    /// along `dir` and the texel (RGBA).
    pub fn stochastic(&self, origin: Vec3, dir: Vec3, pixel: [u32; 2], shift: u32) -> Option<(f32, [u8; 4])> {
        let b = bayer4([pixel[1], pixel[0]], shift ^ SLICE_DITHER_SALT);
        let blend = &self.blend;
        // The lower of the two slicings keeps the low thresholds, the other the high ones.
        let keeps = |s: u32| {
            let alpha = if s == blend.primary { blend.alpha_primary } else { blend.alpha_secondary };
            if (s == blend.primary) == blend.primary_lower { b < alpha } else { b >= 1.0 - alpha }
        };
        self.order
            .iter()
            .filter(|(s, _)| keeps(*s))
            .filter_map(|&(s, j)| self.opaque_hit(s, j, origin, dir))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// The nearest crossing of the ray with the trunk and limbs (the mesh's bark submeshes, which
    /// LOD 1 draws beside the slices, either side of each triangle), its distance along `dir`.
    pub fn trunk(&self, origin: Vec3, dir: Vec3) -> Option<f32> {
        let mesh = &self.impostor.mesh;
        let corner = |i: u32| Vec3::from(mesh.vertices[i as usize].position_model_m);
        mesh.submeshes
            .iter()
            .filter(|s| mesh.materials[s.material as usize].is_bark())
            .flat_map(|s| {
                mesh.indices[s.first_index as usize..(s.first_index + s.index_count) as usize].chunks(3)
            })
            .filter_map(|t| crossing([corner(t[0]), corner(t[1]), corner(t[2])], origin, dir))
            .min_by(f32::total_cmp)
    }
}

/// Where a ray crosses triangle `t` (Möller and Trumbore), its distance along `dir`, if ahead.
fn crossing(t: [Vec3; 3], origin: Vec3, dir: Vec3) -> Option<f32> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = origin - t[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    let distance = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && distance > 0.0).then_some(distance)
}

impl BlendError {
    /// The 4 × 4 block means of two `VIEW_PX`² pictures compared: mean absolute difference per
    /// channel over the blocks either covers, and their coverage ratio.
    pub fn between(sorted: &[[f32; 4]], stochastic: &[[f32; 4]]) -> Self {
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
}
