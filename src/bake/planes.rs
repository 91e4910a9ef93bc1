//! How it works: the planes of a billboard cloud or a slicing, baked into one atlas. Each plane
//! is a `Frame` (its normal and offset, its right and up axes, the extent of what it draws along
//! the three) and the triangles drawn onto it; `bake` gives all planes one texel density and
//! shelf-packs their rectangles (`pack`), renders each plane's triangles orthographically into its
//! rectangle on the GPU (`render`), between depth planes a hair outside its triangles, then reads
//! the atlas back and builds its coverage-preserving mips (`build_mip_chain`, per plane).

use glam::{Mat4, Vec3, Vec4};

use super::fit::FittedPlane;
use super::render::PlaneDraw;
use super::{ALPHA_CUTOFF, Job, LodError, atlas_mips, pack};
use crate::impostor::{MipChain, Plane, build_mip_chain};

/// A plane's frame and the extent of what it draws.
pub(super) struct Frame {
    pub normal: Vec3,
    pub offset_m: f32,
    pub right: Vec3,
    pub up: Vec3,
    /// (min, max) of the drawn vertices along right, up and normal (from the plane).
    pub extent_m: [[f32; 2]; 3],
    /// The triangles drawn onto it (indices into the model's triangle list).
    pub triangles: Vec<u32>,
}

impl Frame {
    /// A fitted plane's frame: facing out of the model, "up" along model +Y, its extent that of
    /// the triangles it draws.
    pub fn fitted(plane: &FittedPlane, triangles: &[[Vec3; 3]], centre: Vec3) -> Self {
        let (mut normal, mut offset_m) = (plane.normal.normalize(), plane.offset_m);
        // Face out of the model, so the front shows the outermost surface (up, for a plane
        // through it).
        if offset_m - normal.dot(centre) < 0.0 {
            (normal, offset_m) = (-normal, -offset_m);
        }
        let reference = if normal.y.abs() < 0.99 { Vec3::Y } else { Vec3::NEG_Z };
        let up = (reference - reference.dot(normal) * normal).normalize();
        let right = up.cross(normal);
        let mut frame =
            Self { normal, offset_m, right, up, extent_m: [[0.0; 2]; 3], triangles: plane.triangles.clone() };
        frame.extent_m = frame.extent_of(triangles);
        frame
    }

    /// (min, max) of the frame's triangles along right, up and normal (from the plane); zero
    /// extents without triangles.
    pub fn extent_of(&self, triangles: &[[Vec3; 3]]) -> [[f32; 2]; 3] {
        let mut extent_m = [[f32::INFINITY, f32::NEG_INFINITY]; 3];
        for &t in &self.triangles {
            for p in triangles[t as usize] {
                let along = [self.right.dot(p), self.up.dot(p), self.normal.dot(p) - self.offset_m];
                for (k, value) in along.into_iter().enumerate() {
                    extent_m[k] = [extent_m[k][0].min(value), extent_m[k][1].max(value)];
                }
            }
        }
        extent_m.map(|[lo, hi]| if lo <= hi { [lo, hi] } else { [0.0, 0.0] })
    }
}

/// Planes baked into one atlas.
pub(super) struct Baked {
    pub planes: Vec<Plane>,
    pub atlas: MipChain,
    /// The atlas's texel density, texels per metre, the same on every plane.
    pub texels_per_m: f32,
}

/// Bakes `frames` into one atlas of `texels` × `texels`.
pub(super) fn bake(job: &Job, frames: &[Frame], texels: u32) -> Result<Baked, LodError> {
    let sizes: Vec<[f32; 2]> =
        frames.iter().map(|f| [0, 1].map(|k| f.extent_m[k][1] - f.extent_m[k][0])).collect();
    let (mip_count, align) = atlas_mips(texels);
    let packing = pack::pack(&sizes, texels, align).ok_or(LodError::Pack { planes: frames.len(), texels })?;
    let density = packing.texels_per_m;
    let mut planes = Vec::new();
    let mut draws = Vec::new();
    for (frame, rect) in frames.iter().zip(&packing.rects) {
        // The rectangle's exact extent in metres, centred on what the plane draws.
        let [[u0, u1], [v0, v1]] = [0, 1].map(|k| {
            let (mid, half) = (
                0.5 * (frame.extent_m[k][0] + frame.extent_m[k][1]),
                [rect.width, rect.height][k] as f32 / (2.0 * density),
            );
            [mid - half, mid + half]
        });
        let [w0, w1] = frame.extent_m[2];
        let margin = 0.01 * (w1 - w0) + 1e-4;
        let (near, far) = (w1 + margin, w0 - margin);
        let origin = frame.offset_m * frame.normal;
        let at = |u: f32, v: f32| (origin + u * frame.right + v * frame.up).to_array();
        let corner = |x: u32, y: u32| [x as f32 / texels as f32, y as f32 / texels as f32];
        planes.push(Plane {
            corners_model_m: [at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)],
            normal_model: frame.normal.to_array(),
            uv_min: corner(rect.x, rect.y),
            uv_max: corner(rect.x + rect.width, rect.y + rect.height),
        });
        // Rows of the clip-from-model transform: x from right, y from up, depth 0 at the front.
        let row = |axis: Vec3, scale: f32, shift: f32| {
            Vec4::new(axis.x * scale, axis.y * scale, axis.z * scale, shift)
        };
        let depth_scale = 1.0 / (near - far);
        let rows = [
            row(frame.right, 2.0 / (u1 - u0), -(u1 + u0) / (u1 - u0)),
            row(frame.up, 2.0 / (v1 - v0), -(v1 + v0) / (v1 - v0)),
            row(-frame.normal, depth_scale, (frame.offset_m + near) * depth_scale),
            Vec4::new(0.0, 0.0, 0.0, 1.0),
        ];
        let clip_from_model = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
        draws.push(PlaneDraw { clip_from_model, rect: *rect, triangles: frame.triangles.clone() });
    }
    let texels_level0 = job.baker.render_atlas(job.gpu, job.mesh, job.uploaded, &draws, texels)?;
    let atlas =
        build_mip_chain(texels_level0, [texels, texels], mip_count, Some(ALPHA_CUTOFF), &packing.rects);
    Ok(Baked { planes, atlas, texels_per_m: density })
}
