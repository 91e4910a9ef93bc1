//! How it works: the manifest is plain serde over TOML. Its `format_version` is read alone first
//! (every other field ignored), so a folder of another version is reported as such rather than as
//! a malformed manifest. Images are listed per mip with their size; the mesh by its counts.

use serde::{Deserialize, Serialize};

/// `impostor.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The format the folder is written in, [`FORMAT_VERSION`](super::FORMAT_VERSION) by this
    /// build; read alone before the rest.
    pub format_version: u32,
    /// The model's name: its folder's name, the glTF file's stem.
    pub name: String,
    /// Always "straight": colour is not premultiplied by alpha.
    pub alpha: String,
    /// Atlas texels with alpha below this are not part of the model.
    pub alpha_cutoff: f32,
    /// Encloses every vertex of the mesh, in model space; its centre is at mid-height.
    pub bounding_sphere: BoundingSphere,
    /// The real mesh's file, counts and submeshes.
    pub mesh: MeshEntry,
    /// The mesh's materials, indexed by [`Submesh::material`].
    pub materials: Vec<MaterialEntry>,
    /// The billboard clouds, finest first.
    pub lods: Vec<LodEntry>,
    /// The crown's slicings (`slicing_mip{M}.png`), when baked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slicing: Option<SlicingEntry>,
}

/// The crown's slicings: how many, the crown and trunk it split the mesh into, the slices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SlicingEntry {
    /// Slicings, evenly spread around the vertical.
    pub orientations: u32,
    /// Slices per slicing.
    pub slices: u32,
    /// Triangles of the crown, drawn onto the slices.
    pub crown_triangles: u32,
    /// Triangles of the trunk and limbs, left to the mesh.
    pub trunk_triangles: u32,
    /// The slices, orientation-major, and their atlas.
    pub lod: LodEntry,
}

/// Only the version, read before the rest.
#[derive(Deserialize)]
pub struct VersionOnly {
    /// The manifest's `format_version`; every other key is ignored, whatever its shape.
    pub format_version: u32,
}

/// A sphere in model space (metres, +Y up).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoundingSphere {
    /// The centre; for a model's sphere, the middle of its bounding box (so at mid-height).
    pub centre_model_m: [f32; 3],
    /// Reaches the farthest point, and a hair beyond so that rounding leaves none out.
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

    /// Whether point `p` (model space) lies inside the sphere or on it.
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
    /// Unit normal in model space, pointing to the plane's front: the side from which its atlas
    /// image reads correctly, facing out of the model.
    pub normal_model: [f32; 3],
    /// The plane's atlas rectangle, uv in [0, 1] with (0, 0) at the image's top left.
    pub uv_min: [f32; 2],
    /// The rectangle's opposite corner: largest u and v, its bottom right (v grows downwards).
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
    /// Levels stored, mip 0 included; as many as `files`.
    pub mip_count: u32,
    /// One file per mip, finest first, relative to the model's folder.
    pub files: Vec<String>,
}

/// One level of detail: a billboard cloud and its atlas (`lod{L}_mip{M}.png`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LodEntry {
    /// The fit's tolerance in metres: every triangle drawn on a plane lies within this of it,
    /// except the few the planes could not cover.
    pub epsilon_m: f32,
    /// The atlas's size and its PNGs, one per mip.
    pub atlas: ImageEntry,
    /// The cloud's planes: corners in model space, rectangles in atlas uv.
    pub planes: Vec<Plane>,
}

/// The real mesh: where it is stored and what loading checks it holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeshEntry {
    /// The mesh file, relative to the model's folder (`mesh.bin`).
    pub file: String,
    /// [`MeshVertex`](super::MeshVertex) structs in the file; loading fails on any other number.
    pub vertex_count: u32,
    /// `u32` indices in the file, three per triangle; loading fails on any other number.
    pub index_count: u32,
    /// One range of the index buffer per material that draws anything, in material order.
    pub submeshes: Vec<Submesh>,
}

/// A range of the index buffer drawn with one material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Submesh {
    /// Index of its material in the mesh's materials.
    pub material: u32,
    /// Where the range starts, counted in indices from the index buffer's start.
    pub first_index: u32,
    /// Indices in the range: three per triangle.
    pub index_count: u32,
}

/// glTF's alpha modes that the models use (`BLEND` is read as `MASK`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlphaMode {
    /// Every texel is drawn: the texture's alpha is not a mask (glTF `OPAQUE`).
    Opaque,
    /// Texels with alpha below the material's cutoff are cut out (glTF `MASK`, and `BLEND`).
    Mask,
}

/// A material of the mesh, its texture stored as PNGs (`material{K}_mip{M}.png`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialEntry {
    /// The glTF material's name (`material{K}` when it has none).
    pub name: String,
    /// Linear RGBA, multiplied with the texture.
    pub base_color_factor: [f32; 4],
    /// Whether the texture's alpha cuts texels out.
    pub alpha_mode: AlphaMode,
    /// For [`AlphaMode::Mask`]: texels below this alpha are cut out.
    pub alpha_cutoff: f32,
    /// Both faces are meant to be seen (glTF `doubleSided`), as for leaves.
    pub double_sided: bool,
    /// The base-colour texture (RGBA8 sRGB, straight alpha), one PNG per mip; absent for a plain
    /// colour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<ImageEntry>,
    /// How its primitives shed detail with distance (continuous LOD); absent: drawn whole.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub detail: Option<super::Detail>,
}
