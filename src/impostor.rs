//! How it works: an impostor is everything the seed-drawing pass (pass 4) needs to draw one model
//! (a tree, a bush, a rock) at any distance: the real mesh up close and, further out, a *billboard
//! cloud* at three levels of detail: a few textured planes fitted to the model (Décoret et al.
//! 2003, Fuhrmann et al. 2005), whose atlas holds the geometry near each plane rendered
//! orthographically onto it. The baker (`bake`) makes impostors from glTF models; [`load`] reads
//! one back, ready for upload: plane vertices and indices ([`ImpostorLod::vertices`]), atlas texels
//! per mip, mesh vertices, indices and materials.
//!
//! Model space is the glTF's: metres, +Y up, the model's base at y = 0. On disk, one folder per
//! model, `DIR/<model>/`:
//! - `impostor.toml`, the manifest ([`manifest::Manifest`], `format_version` first): the bounding
//!   sphere, the alpha cutoff, per LOD the fit tolerance ε, the atlas (size, mip count, one PNG per
//!   mip) and the planes (4 corners in model space, counter-clockwise seen from the side the
//!   normal points to, and the plane's atlas rectangle as uv min/max), the mesh's submeshes and
//!   materials.
//! - `lod{L}_mip{M}.png`: LOD L's atlas, mip M. RGBA8, colour in sRGB, **straight** (not
//!   premultiplied) alpha. Colour is the unlit base colour (texture × factor): shading, ground
//!   colour follow-up and cross-fades are the draw pass's, as in the paper's FS4. Draw with an alpha test at `alpha_cutoff` (or alpha to coverage). Texels
//!   that no geometry covers carry the colour of the nearest covered texel (dilation), so bilinear
//!   filtering never darkens edges. Mips are box-filtered in linear light weighted by alpha, and
//!   each plane's alpha is rescaled per mip so that the fraction of its texels passing the cutoff
//!   stays that of mip 0 (Castaño's coverage-preserving mips): distant leaves neither vanish nor
//!   bloat. Every rectangle starts and ends on a multiple of 2^(mips-1) texels, with at least that
//!   many empty texels between rectangles, so no mip mixes two planes. uv (0, 0) is the top-left
//!   corner of the image's top-left texel; corner 0 of a plane (its bottom-left) sits at
//!   (`uv_min.x`, `uv_max.y`).
//! - `slicing_mip{M}.png`, with the manifest's optional `slicing` table: the crown's slicings
//!   ([`Slicing`], Jakulin 2000), when baked: slices as planes, same conventions as the atlases.
//! - `mesh.bin` ([`mesh_file`]): the real mesh, vertices ([`MeshVertex`]) then `u32` indices,
//!   with a checksum; `material{K}_mip{M}.png`: material K's base-colour texture, same conventions
//!   as the atlases (alpha-masked leaf textures get coverage-preserving mips too).
//!
//! [`save`] writes a model's folder beside its final place and puts it in place (`crate::publish`),
//! so a folder is the previous complete impostor or the new one (or, only where the file system
//! cannot exchange two folders and the baker was killed between the fallback's renames, absent
//! until the next bake there puts the previous one back). A folder of another format version is
//! reported as such ([`ImpostorError::Version`]): bake it again.

pub mod detail;
pub mod manifest;
pub mod mesh_file;
pub mod mips;
pub mod slicing;
mod store;

use std::path::PathBuf;

use bytemuck::{Pod, Zeroable};
use thiserror::Error;

pub use detail::Detail;
pub use manifest::{AlphaMode, BoundingSphere, Plane, Submesh};
pub use mips::{MipChain, TexelRect, build_mip_chain, mip_size};
pub use store::{is_current, load, models, replace_folder, save};

/// The on-disk format's version: a reader refuses any other. 2: mesh vertices carry their leaf's
/// pivot (the wind's flutter). 3: materials may carry their continuous LOD ([`Detail`]).
pub const FORMAT_VERSION: u32 = 3;
/// The glTF vertex attribute that holds each vertex's leaf pivot ([`MeshVertex::pivot_model_m`]):
/// an application attribute (glTF names those with a leading underscore), written by the tree
/// generator and read by the baker.
pub const PIVOT_ATTRIBUTE: &str = "_PIVOT";
/// The manifest's name inside a model's folder.
pub const MANIFEST_FILE: &str = "impostor.toml";
/// The real mesh's name inside a model's folder.
pub const MESH_FILE: &str = "mesh.bin";

/// Why an impostor could not be saved, loaded or listed; each names the file or model at fault.
#[derive(Debug, Error)]
pub enum ImpostorError {
    /// A file or folder of the store could not be read, written, created, renamed or listed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder the operation was on.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// `impostor.toml` is not TOML, or lacks or mistypes a key of this format version.
    #[error("{path}: malformed impostor manifest: {source}")]
    Manifest {
        /// The manifest's path.
        path: PathBuf,
        /// The parser's error, boxed so that every `Result` stays small.
        source: Box<toml::de::Error>,
    },
    /// The manifest or `mesh.bin` was written by another format version: bake the model again.
    #[error(
        "{path}: impostor format version {found}, this build reads version {expected}: bake the model again"
    )]
    Version {
        /// The file whose version differs.
        path: PathBuf,
        /// The version the file declares.
        found: u32,
        /// The version this build reads and writes ([`FORMAT_VERSION`]).
        expected: u32,
    },
    /// An atlas or material PNG could not be written, opened or decoded.
    #[error("{path}: {source}")]
    Image {
        /// The PNG's path.
        path: PathBuf,
        /// The `image` crate's error.
        source: image::ImageError,
    },
    /// A file reads but holds the wrong thing: `mesh.bin` with a bad magic, length, checksum or
    /// index, a mip of the wrong size, or counts that disagree with the manifest.
    #[error("{path}: {reason}")]
    Invalid {
        /// The offending file (the manifest for a wrong list of mip files).
        path: PathBuf,
        /// What is wrong with it, for the message.
        reason: String,
    },
    /// An impostor breaks a rule the draw passes rely on (plain name, level sizes, atlas
    /// rectangles inside the atlas, submeshes and indices in range): checked on save and on load.
    #[error("impostor {name:?}: {reason}")]
    Inconsistent {
        /// The impostor's model name.
        name: String,
        /// Which rule it breaks, for the message.
        reason: String,
    },
    /// The manifest could not be serialised to TOML; holds the serialiser's message.
    #[error("writing an impostor manifest: {0}")]
    ManifestWrite(String),
}

/// One model, everything a draw pass needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Impostor {
    /// The model's name (its folder's name: the glTF file's stem).
    pub name: String,
    /// Encloses every vertex of the mesh, in model space; its centre is at mid-height.
    pub bounding_sphere: BoundingSphere,
    /// Atlas texels with alpha below this are not part of the model.
    pub alpha_cutoff: f32,
    /// The billboard clouds, finest first (17, 8 and 2 planes by default).
    pub lods: Vec<ImpostorLod>,
    /// The crown's slicings (Jakulin 2000), when baked (`terramp-data bake --slicings`).
    pub slicing: Option<Slicing>,
    /// The real mesh, for close-up drawing.
    pub mesh: Mesh,
}

/// A model's crown as slicings (Jakulin 2000): `orientations` sets of `slices` parallel slices,
/// the sets' normals evenly spread around the vertical (orientation i at azimuth 2π i /
/// orientations from model +X towards +Z), each set's slices equidistant across the crown, every
/// slice as wide and tall as its set's box. The trunk and limbs (the mesh's bark materials,
/// [`Material::is_bark`]) are not sliced: they stay the mesh's.
#[derive(Debug, Clone, PartialEq)]
pub struct Slicing {
    /// Slicings, evenly spread around the vertical.
    pub orientations: u32,
    /// Slices per slicing.
    pub slices: u32,
    /// The slices as planes (orientation-major: slice j of orientation i is plane i · slices + j,
    /// its normal the orientation) and their atlas; ε is half the distance between slices, the
    /// farthest a primitive's centroid lies from its slice.
    pub lod: ImpostorLod,
    /// Triangles of the crown, drawn onto the slices.
    pub crown_triangles: u32,
    /// Triangles of the trunk and limbs, left to the mesh.
    pub trunk_triangles: u32,
}

/// One level of detail: a billboard cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpostorLod {
    /// The fit's tolerance: every triangle drawn on a plane lies within this of it, except the
    /// few the planes could not cover, which go to the nearest plane.
    pub epsilon_m: f32,
    /// The cloud's textured planes: corners in model space, rectangles in [`Self::atlas`].
    pub planes: Vec<Plane>,
    /// RGBA8 sRGB, straight alpha, one level per mip.
    pub atlas: MipChain,
}

/// A billboard-cloud vertex, as the draw pass uploads it: 4 per plane, in the order of
/// [`Plane::corners_model_m`].
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct PlaneVertex {
    /// A corner of the plane in model space (metres, +Y up, base at y = 0).
    pub position_model_m: [f32; 3],
    /// The plane's front normal (the atlas image reads correctly from this side).
    pub normal_model: [f32; 3],
    /// The corner's place on the LOD's atlas: uv in [0, 1], (0, 0) at the image's top left.
    pub uv_atlas: [f32; 2],
}

impl ImpostorLod {
    /// Four vertices per plane, planes in order.
    pub fn vertices(&self) -> Vec<PlaneVertex> {
        self.planes
            .iter()
            .flat_map(|plane| {
                let uvs = plane.corner_uvs();
                (0..4).map(move |k| PlaneVertex {
                    position_model_m: plane.corners_model_m[k],
                    normal_model: plane.normal_model,
                    uv_atlas: uvs[k],
                })
            })
            .collect()
    }

    /// Two triangles per plane (counter-clockwise from the front) into [`Self::vertices`]. Draw
    /// without culling: a billboard is seen from both sides.
    pub fn indices(&self) -> Vec<u32> {
        (0..self.planes.len() as u32).flat_map(|p| [0, 1, 2, 0, 2, 3].map(|k| 4 * p + k)).collect()
    }
}

/// A mesh vertex (`mesh.bin` stores these as they are, 44 bytes each).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct MeshVertex {
    /// Model space (metres, +Y up, base at y = 0), the glTF's node transforms applied.
    pub position_model_m: [f32; 3],
    /// Unit vertex normal in model space (computed from the faces when the glTF has none).
    pub normal_model: [f32; 3],
    /// Base-colour texture coordinates ((0, 0) at the image's top left, repeating).
    pub uv: [f32; 2],
    /// Where the vertex's leaf hangs from its stem, model space: the wind turns the leaf about it
    /// (`seeds::wind`). The vertex's own position where nothing flutters: bark, rigid parts, and
    /// every vertex of a model without the glTF attribute `_PIVOT`.
    pub pivot_model_m: [f32; 3],
}

/// The real mesh: one vertex buffer, one index buffer, one submesh per material.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Every triangle primitive's vertices, all in one buffer.
    pub vertices: Vec<MeshVertex>,
    /// Triangle lists, counter-clockwise front faces.
    pub indices: Vec<u32>,
    /// One range of [`Self::indices`] per material that draws anything, in material order.
    pub submeshes: Vec<Submesh>,
    /// Indexed by [`Submesh::material`]; a plain white `default` is added for primitives the glTF
    /// gives no material.
    pub materials: Vec<Material>,
}

impl Mesh {
    /// Triangle `t`'s material index.
    pub fn material_of_triangle(&self, t: usize) -> Option<u32> {
        let index = (3 * t) as u32;
        self.submeshes
            .iter()
            .find(|s| (s.first_index..s.first_index + s.index_count).contains(&index))
            .map(|s| s.material)
    }
}

/// A glTF metallic-roughness material reduced to what foliage and rocks use.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The glTF material's name (`material{K}` when it has none), for messages and the manifest.
    pub name: String,
    /// Linear RGBA, multiplied with the texture.
    pub base_color_factor: [f32; 4],
    /// Whether the texture's alpha cuts texels out ([`AlphaMode::Mask`]) or is ignored.
    pub alpha_mode: AlphaMode,
    /// For [`AlphaMode::Mask`]: texels below this alpha are cut out.
    pub alpha_cutoff: f32,
    /// Both faces are meant to be seen (glTF `doubleSided`), as for leaves.
    pub double_sided: bool,
    /// RGBA8 sRGB, straight alpha, with mips; `None` for a plain colour.
    pub texture: Option<MipChain>,
    /// How its primitives shed detail with distance (generated trees); `None`: drawn whole.
    pub detail: Option<Detail>,
}

impl Material {
    /// Whether it is bark (a trunk, a branch), by its name: glTF says nothing of what a material
    /// is, and the models name theirs (`Bark`, `Birch_Bark`, the generated trees' `bark 0`). Bark
    /// keeps its own colour where foliage takes on the ground's, and stays a mesh in slicings.
    pub fn is_bark(&self) -> bool {
        let name = self.name.to_ascii_lowercase();
        ["bark", "trunk", "wood"].iter().any(|word| name.contains(word))
    }
}

#[cfg(test)]
mod tests;
