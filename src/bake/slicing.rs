//! How it works: Jakulin's slicings (2000) of a model's crown. The mesh splits into the solid
//! part, its bark materials (`Material::is_bark`: trunk and limbs, left to the mesh), and the
//! sparse crown (every other material). Each of `orientations` slicings has a horizontal normal,
//! evenly spread around the vertical (`impostor::slicing::orientation`); its box spans the crown along the normal,
//! "right" (up × normal) and up, and is cut into `slices` equal slabs. Every crown triangle goes
//! to the slice of its slab in each slicing, by its centroid (the paper's assignment), and each
//! slice is baked like a billboard-cloud plane (`planes`): orthographically, from the side its
//! normal points to, every slice of a slicing as wide and tall as the slicing's box, so the slices
//! line up.

use glam::Vec3;

use super::planes::{self, Frame};
use super::{Job, LodError};
use crate::impostor::slicing::orientation;
use crate::impostor::{ImpostorLod, Mesh, Slicing};

/// How a model's crown is sliced: `orientations` slicings of `slices` parallel slices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SlicingOptions {
    /// Slicings, evenly spread around the vertical (the paper: 6).
    pub orientations: u32,
    /// Slices per slicing (the paper: 5).
    pub slices: u32,
}

impl Default for SlicingOptions {
    fn default() -> Self {
        Self { orientations: 6, slices: 5 }
    }
}

/// The mesh's triangles split into (crown, trunk): indices into its triangle list, by whether the
/// material that draws them is bark.
pub(super) fn split(mesh: &Mesh) -> (Vec<u32>, Vec<u32>) {
    let (mut crown, mut trunk) = (Vec::new(), Vec::new());
    for submesh in &mesh.submeshes {
        let bark = mesh.materials.get(submesh.material as usize).is_some_and(|m| m.is_bark());
        let first = submesh.first_index / 3;
        let triangles = first..first + submesh.index_count / 3;
        if bark { trunk.extend(triangles) } else { crown.extend(triangles) }
    }
    (crown, trunk)
}

/// (min, max) of the vertices of `crown` (indices into `triangles`) along `axis`.
fn span(triangles: &[[Vec3; 3]], crown: &[u32], axis: Vec3) -> [f32; 2] {
    let points = crown.iter().flat_map(|&t| triangles[t as usize]);
    points.fold([f32::INFINITY, f32::NEG_INFINITY], |[lo, hi], p| [lo.min(axis.dot(p)), hi.max(axis.dot(p))])
}

/// The slices of every slicing of `crown` (indices into `triangles`), orientation-major.
pub(super) fn frames(triangles: &[[Vec3; 3]], crown: &[u32], options: SlicingOptions) -> Vec<Frame> {
    let n = options.slices.max(1);
    let mut frames = Vec::new();
    for i in 0..options.orientations {
        let normal = orientation(i, options.orientations);
        let up = Vec3::Y;
        let right = up.cross(normal);
        let span = |axis: Vec3| span(triangles, crown, axis);
        let ([r0, r1], [u0, u1], [d0, d1]) = (span(right), span(up), span(normal));
        let width_m = (d1 - d0) / n as f32;
        let slab_of = |t: u32| {
            let centroid = triangles[t as usize].iter().sum::<Vec3>() / 3.0;
            (((normal.dot(centroid) - d0) / width_m) as u32).min(n - 1)
        };
        for j in 0..n {
            let mut frame = Frame {
                normal,
                offset_m: d0 + (j as f32 + 0.5) * width_m,
                right,
                up,
                extent_m: [[r0, r1], [u0, u1], [0.0, 0.0]],
                triangles: crown.iter().copied().filter(|&t| width_m > 0.0 && slab_of(t) == j).collect(),
            };
            // The box's width and height for every slice; the depth of its own triangles.
            frame.extent_m[2] = frame.extent_of(triangles)[2];
            frames.push(frame);
        }
    }
    frames
}

/// Bakes `job`'s crown into slicings on an atlas of `texels`; `None` for a model without a crown
/// (all bark, or nothing but points), which stays its mesh.
pub(super) fn bake(job: &Job, options: SlicingOptions, texels: u32) -> Result<Option<Slicing>, LodError> {
    let (crown, trunk) = split(job.mesh);
    if crown.is_empty() || options.orientations == 0 || options.slices == 0 {
        return Ok(None);
    }
    let frames = frames(job.triangles, &crown, options);
    // ε: half a slab of the widest slicing, the farthest a centroid lies from its slice.
    let slab_m = (0..options.orientations)
        .map(|i| {
            let [d0, d1] = span(job.triangles, &crown, orientation(i, options.orientations));
            (d1 - d0) / options.slices as f32
        })
        .fold(0.0, f32::max);
    let baked = planes::bake(job, &frames, texels)?;
    Ok(Some(Slicing {
        orientations: options.orientations,
        slices: options.slices,
        lod: ImpostorLod { epsilon_m: 0.5 * slab_m, planes: baked.planes, atlas: baked.atlas },
        crown_triangles: crown.len() as u32,
        trunk_triangles: trunk.len() as u32,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small triangles scattered through a 4 × 6 × 2 m box (x, y, z).
    fn crown() -> Vec<[Vec3; 3]> {
        (0..200)
            .map(|i| {
                let f = |k: u32| crate::seeds::unit(crate::seeds::pcg(i * 3 + k));
                let c = Vec3::new(4.0 * f(0) - 2.0, 6.0 * f(1), 2.0 * f(2) - 1.0);
                [c, c + Vec3::new(0.05, 0.0, 0.0), c + Vec3::new(0.0, 0.05, 0.0)]
            })
            .collect()
    }

    #[test]
    fn every_crown_triangle_goes_to_one_slice_of_each_slicing_the_nearest_to_its_centroid() {
        let triangles = crown();
        let all: Vec<u32> = (0..triangles.len() as u32).collect();
        let options = SlicingOptions::default();
        let frames = frames(&triangles, &all, options);
        assert_eq!(frames.len(), 30);
        for (i, slicing) in frames.chunks(options.slices as usize).enumerate() {
            let mut seen: Vec<u32> = slicing.iter().flat_map(|f| f.triangles.clone()).collect();
            seen.sort_unstable();
            assert_eq!(seen, all, "slicing {i} loses or repeats triangles");
            let spacing = slicing[1].offset_m - slicing[0].offset_m;
            for f in slicing {
                assert_eq!(f.normal, orientation(i as u32, options.orientations));
                // Slices share their slicing's box, so they line up.
                assert_eq!((f.extent_m[0], f.extent_m[1]), (slicing[0].extent_m[0], slicing[0].extent_m[1]));
                for &t in &f.triangles {
                    let centroid = triangles[t as usize].iter().sum::<Vec3>() / 3.0;
                    let from_slice = (f.normal.dot(centroid) - f.offset_m).abs();
                    assert!(
                        from_slice <= 0.5 * spacing + 1e-4,
                        "{from_slice} from its slice, {spacing} apart"
                    );
                }
            }
        }
    }
}
