//! How it works: the manifest is plain serde over TOML. Its `format_version` is read alone first
//! (every other field ignored), so a folder of another version is reported as such rather than as
//! a malformed manifest. Images are listed per mip with their size; the mesh by its counts.

use serde::{Deserialize, Serialize};

/// `impostor.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub format_version: u32,
    pub name: String,
    /// Always "straight": colour is not premultiplied by alpha.
    pub alpha: String,
    pub alpha_cutoff: f32,
    pub bounding_sphere: BoundingSphere,
    pub mesh: MeshEntry,
    pub materials: Vec<MaterialEntry>,
    pub lods: Vec<LodEntry>,
}

/// Only the version, read before the rest.
#[derive(Deserialize)]
pub struct VersionOnly {
    pub format_version: u32,
}

/// A sphere in model space (metres, +Y up).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoundingSphere {
    pub centre_model_m: [f32; 3],
    pub radius_m: f32,
}

impl BoundingSphere {
    /// Centred on the points' bounding box (so at mid-height, as the paper's seeds expect), with
    /// the radius of the farthest point, grown by a hair so that rounding cannot leave a point out.
    pub fn enclosing(points: impl IntoIterator<Item = [f32; 3]> + Clone) -> Self {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in points.clone() {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if lo[0] > hi[0] {
            return Self { centre_model_m: [0.0; 3], radius_m: 0.0 };
        }
        let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        let radius = points
            .into_iter()
            .map(|p| (0..3).map(|k| f64::from(p[k] - centre[k]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        Self { centre_model_m: centre, radius_m: (radius * (1.0 + 1e-5) + 1e-6) as f32 }
    }

    pub fn contains(&self, p: [f32; 3]) -> bool {
        let d2: f32 = (0..3).map(|k| (p[k] - self.centre_model_m[k]).powi(2)).sum();
        d2.sqrt() <= self.radius_m
    }
}

/// A textured plane of a billboard cloud.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// Model space (metres): bottom-left, bottom-right, top-right, top-left as seen from the front
    /// (the side `normal_model` points to), so counter-clockwise from the front. "Up" is model +Y
    /// projected onto the plane (+Z for a horizontal plane).
    pub corners_model_m: [[f32; 3]; 4],
    pub normal_model: [f32; 3],
    /// The plane's atlas rectangle, uv in [0, 1] with (0, 0) at the image's top left.
    pub uv_min: [f32; 2],
    pub uv_max: [f32; 2],
}

impl Plane {
    /// The atlas uv of each corner of [`Self::corners_model_m`].
    pub fn corner_uvs(&self) -> [[f32; 2]; 4] {
        let ([u0, v0], [u1, v1]) = (self.uv_min, self.uv_max);
        [[u0, v1], [u1, v1], [u1, v0], [u0, v0]]
    }
}

/// An image stored as one PNG per mip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageEntry {
    /// Mip 0's width and height; mip M is `max(1, size >> M)`.
    pub size: [u32; 2],
    pub mip_count: u32,
    /// One file per mip, finest first, relative to the model's folder.
    pub files: Vec<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LodEntry {
    pub epsilon_m: f32,
    pub atlas: ImageEntry,
    pub planes: Vec<Plane>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshEntry {
    pub file: String,
    pub vertex_count: u32,
    pub index_count: u32,
    pub submeshes: Vec<Submesh>,
}

/// A range of the index buffer drawn with one material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Submesh {
    pub material: u32,
    pub first_index: u32,
    pub index_count: u32,
}

/// glTF's alpha modes that the models use (`BLEND` is read as `MASK`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlphaMode {
    Opaque,
    Mask,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialEntry {
    pub name: String,
    pub base_color_factor: [f32; 4],
    pub alpha_mode: AlphaMode,
    pub alpha_cutoff: f32,
    pub double_sided: bool,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<ImageEntry>,
}
