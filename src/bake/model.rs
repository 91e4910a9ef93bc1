//! How it works: reads a glTF model (`.glb`, or `.gltf` with its buffers and images beside it)
//! into terramp's impostor [`Mesh`]: every triangle primitive of the default scene, node
//! transforms applied (normals by the inverse transpose, winding flipped under a mirroring
//! transform), grouped into one submesh per material. Materials keep what foliage and rocks use:
//! the base-colour factor and texture (decoded by `image`: PNG and JPEG; coverage-preserving mips
//! for alpha-masked ones), the alpha mode and cutoff, double-sidedness, and the continuous LOD the
//! tree generator writes in a material's `extras` (`impostor::Detail`, in the mesh's own units:
//! the generator's nodes are not transformed). Missing normals are computed from the faces;
//! missing texture coordinates are 0.

use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Vec3};
use gltf::Semantic;
use gltf::accessor::DataType::{self, F32, U8, U16, U32};
use gltf::accessor::Dimensions::{self, Scalar, Vec2};
use thiserror::Error;

use crate::impostor::detail::DETAIL_EXTRAS;
use crate::impostor::{
    AlphaMode, Detail, Material, Mesh, MeshVertex, MipChain, PIVOT_ATTRIBUTE, Submesh, build_mip_chain,
};

/// What makes a model unreadable. The error carrying it names the model's file.
#[derive(Debug, Error)]
pub enum ModelError {
    /// The model file could not be read.
    #[error("reading it: {0}")]
    Read(#[source] std::io::Error),
    /// The file does not parse as glTF (JSON `.gltf` or binary `.glb`).
    #[error("not a valid glTF model: {0}")]
    NotGltf(#[source] gltf::Error),
    /// A primitive takes its positions from an accessor the file does not have.
    #[error(
        "not a valid glTF model: mesh {mesh}, primitive {primitive} takes its POSITION from accessor \
         {accessor}, and the file has {accessors} accessors"
    )]
    NoSuchAccessor {
        /// The mesh, counted from 0.
        mesh: usize,
        /// The primitive in it, counted from 0.
        primitive: usize,
        /// The accessor it names.
        accessor: usize,
        /// Accessors in the file.
        accessors: usize,
    },
    /// A `.glb` header gives the file a length shorter than the header itself.
    #[error("not a valid glTF model: the GLB header gives a length of {length} bytes, under its own 12")]
    GlbLength {
        /// The length the header gives, bytes.
        length: u32,
    },
    /// A buffer or image is embedded as a `data:` URI, which the baker does not decode.
    #[error("unusable glTF model: embedded data URIs are not supported: use a .glb")]
    DataUri,
    /// A buffer or image file that the model refers to beside it could not be read.
    #[error("unusable glTF model: reading {file}: {source}")]
    Beside {
        /// That file, resolved against the model's folder.
        file: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A buffer refers to the `.glb` binary chunk and the file has none.
    #[error("unusable glTF model: the binary chunk is missing")]
    NoBinaryChunk,
    /// A buffer's data is shorter than its declared `byteLength`.
    #[error("unusable glTF model: buffer {index} holds {found} bytes, {declared} declared")]
    ShortBuffer {
        /// The buffer's glTF index.
        index: usize,
        /// Bytes its data holds.
        found: usize,
        /// Bytes its `byteLength` declares.
        declared: usize,
    },
    /// An image's buffer view names no buffer or reaches outside its buffer.
    #[error("unusable glTF model: image {image}: {problem}")]
    ImageView {
        /// The image's glTF index.
        image: usize,
        /// Which of the two, for the message.
        problem: &'static str,
    },
    /// An image (PNG or JPEG) could not be decoded.
    #[error("unusable glTF model: image {image}: decoding: {source}")]
    ImageDecode {
        /// The image's glTF index.
        image: usize,
        /// The `image` crate's error.
        source: image::ImageError,
    },
    /// The file has no scene to take the meshes from.
    #[error("unusable glTF model: the file has no scene")]
    NoScene,
    /// A triangle primitive has no `POSITION` attribute.
    #[error("unusable glTF model: mesh {mesh}: a primitive without positions")]
    NoPositions {
        /// The glTF index of the mesh holding the primitive.
        mesh: usize,
    },
    /// An accessor the baker reads is of another type, sparse, empty, or lies outside its buffer
    /// view (the glTF crate's reader assumes all this, and would panic).
    #[error("unusable glTF model: mesh {mesh}: {what} accessor {accessor}: {problem}")]
    BadAccessor {
        /// The glTF index of the mesh holding the primitive.
        mesh: usize,
        /// What the accessor holds (positions, normals, texture coordinates, indices).
        what: &'static str,
        /// The accessor's glTF index.
        accessor: usize,
        /// What is wrong with it.
        problem: String,
    },
    /// A node is reached twice from the scene: the node hierarchy is not a tree.
    #[error("unusable glTF model: node {node} is reached twice from the scene (the nodes must form a tree)")]
    NodeCycle {
        /// The node's glTF index.
        node: usize,
    },
    /// A primitive's index count is not a multiple of 3, or an index points past its vertices.
    #[error("unusable glTF model: mesh {mesh}: bad triangle indices")]
    BadIndices {
        /// The glTF index of the mesh holding the primitive.
        mesh: usize,
    },
    /// A primitive's `_PIVOT` attribute (each vertex's leaf pivot) is not one float VEC3 per
    /// vertex, or its data lies outside its buffer.
    #[error("unusable glTF model: mesh {mesh}: _PIVOT is not one float VEC3 per vertex")]
    BadPivots {
        /// The glTF index of the mesh holding the primitive.
        mesh: usize,
    },
    /// A material's `extras` hold a `terramp_detail` (continuous LOD) that does not parse or
    /// gives no positive size.
    #[error("unusable glTF model: material {material}: terramp_detail: {reason}")]
    BadDetail {
        /// The material's glTF index.
        material: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// The scene holds no triangle at all (non-triangle primitives are skipped).
    #[error("unusable glTF model: no triangles")]
    NoTriangles,
}

/// The mesh of the model at `path`.
pub fn load(path: &Path) -> Result<Mesh, ModelError> {
    let bytes = std::fs::read(path).map_err(ModelError::Read)?;
    let gltf = parse(&bytes)?;
    read(&gltf, path)
}

/// Parses and validates a model's bytes. gltf-json 1.4's validation reads a primitive's POSITION
/// accessor before it checks that the accessor exists, and panics when it does not (found by
/// `fuzz/`'s `gltf_model`): those indices are checked here first, then the crate validates the rest.
/// So is a GLB header's length, from which gltf 1.4 takes the header's 12 bytes unchecked (an
/// underflow, found once the fuzz build checked overflow).
fn parse(bytes: &[u8]) -> Result<gltf::Gltf, ModelError> {
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::Checked;
    if let Some(&[l0, l1, l2, l3]) = bytes.strip_prefix(b"glTF").and_then(|header| header.get(4..8)) {
        let length = u32::from_le_bytes([l0, l1, l2, l3]);
        if length < 12 {
            return Err(ModelError::GlbLength { length });
        }
    }
    let unchecked = gltf::Gltf::from_slice_without_validation(bytes).map_err(ModelError::NotGltf)?;
    let json = unchecked.document.into_json();
    let accessors = json.accessors.len();
    for (mesh, m) in json.meshes.iter().enumerate() {
        for (primitive, p) in m.primitives.iter().enumerate() {
            let position = p.attributes.get(&Checked::Valid(Semantic::Positions));
            if let Some(accessor) = position.map(|a| a.value()).filter(|&a| a >= accessors) {
                return Err(ModelError::NoSuchAccessor { mesh, primitive, accessor, accessors });
            }
        }
    }
    let document = gltf::Document::from_json(json).map_err(ModelError::NotGltf)?;
    Ok(gltf::Gltf { document, blob: unchecked.blob })
}

fn read(gltf: &gltf::Gltf, path: &Path) -> Result<Mesh, ModelError> {
    let beside = |uri: &str| -> Result<Vec<u8>, ModelError> {
        if uri.starts_with("data:") {
            return Err(ModelError::DataUri);
        }
        let file = path.parent().unwrap_or(Path::new(".")).join(uri);
        std::fs::read(&file).map_err(|source| ModelError::Beside { file, source })
    };
    let mut buffers = Vec::new();
    for buffer in gltf.buffers() {
        let data = match buffer.source() {
            // Only the first buffer may be the binary chunk (glTF 2.0 § 4.4.3.3): each would copy it.
            gltf::buffer::Source::Bin if buffer.index() > 0 => return Err(ModelError::NoBinaryChunk),
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or(ModelError::NoBinaryChunk)?,
            gltf::buffer::Source::Uri(uri) => beside(uri)?,
        };
        if data.len() < buffer.length() {
            return Err(ModelError::ShortBuffer {
                index: buffer.index(),
                found: data.len(),
                declared: buffer.length(),
            });
        }
        buffers.push(data);
    }
    let mut materials: Vec<Material> = Vec::new();
    let mut tex_coords: Vec<u32> = Vec::new();
    for material in gltf.materials() {
        let pbr = material.pbr_metallic_roughness();
        let alpha_mode = match material.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask | gltf::material::AlphaMode::Blend => AlphaMode::Mask,
        };
        let alpha_cutoff = material.alpha_cutoff().unwrap_or(0.5);
        let texture = match pbr.base_color_texture() {
            Some(info) => {
                tex_coords.push(info.tex_coord());
                let image = info.texture().source();
                let cutoff = (alpha_mode == AlphaMode::Mask).then_some(alpha_cutoff);
                Some(decode_image(&image, &buffers, &beside, cutoff)?)
            }
            None => {
                tex_coords.push(0);
                None
            }
        };
        let detail = read_detail(material.extras())
            .map_err(|reason| ModelError::BadDetail { material: materials.len(), reason })?;
        materials.push(Material {
            name: material.name().map_or_else(|| format!("material{}", materials.len()), str::to_owned),
            base_color_factor: pbr.base_color_factor(),
            alpha_mode,
            alpha_cutoff,
            double_sided: material.double_sided(),
            texture,
            detail,
        });
    }
    let default_material = materials.len();
    let mut vertices = Vec::new();
    let mut by_material: Vec<Vec<u32>> = vec![Vec::new(); materials.len() + 1];
    let scene = gltf.default_scene().or_else(|| gltf.scenes().next()).ok_or(ModelError::NoScene)?;
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut reached = vec![false; gltf.nodes().len()];
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut reached[node.index()], true) {
            return Err(ModelError::NodeCycle { node: node.index() });
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        stack.extend(node.children().map(|c| (c, world)));
        let Some(mesh) = node.mesh() else { continue };
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        let mirrored = Mat3::from_mat4(world).determinant() < 0.0;
        for primitive in mesh.primitives() {
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                eprintln!("{}: skipping a {:?} primitive (triangles only)", path.display(), primitive.mode());
                continue;
            }
            let material = primitive.material().index().unwrap_or(default_material);
            let set = tex_coords.get(material).copied().unwrap_or(0);
            let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let checked = |what, accessor: Option<gltf::Accessor>, formats: &[(DataType, Dimensions)]| {
                let Some(a) = accessor else { return Ok(()) };
                check_accessor(&a, formats).map_err(|problem| ModelError::BadAccessor {
                    mesh: mesh.index(),
                    what,
                    accessor: a.index(),
                    problem,
                })
            };
            checked("positions", primitive.get(&Semantic::Positions), &[(F32, Dimensions::Vec3)])?;
            checked("normals", primitive.get(&Semantic::Normals), &[(F32, Dimensions::Vec3)])?;
            checked("indices", primitive.indices(), &[(U8, Scalar), (U16, Scalar), (U32, Scalar)])?;
            let uv_formats = [(F32, Vec2), (U8, Vec2), (U16, Vec2)];
            checked("texture coordinates", primitive.get(&Semantic::TexCoords(set)), &uv_formats)?;
            let positions: Vec<Vec3> = reader
                .read_positions()
                .ok_or(ModelError::NoPositions { mesh: mesh.index() })?
                .map(|p| world.transform_point3(Vec3::from(p)))
                .collect();
            let base = vertices.len() as u32;
            let mut indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            if !indices.len().is_multiple_of(3) || indices.iter().any(|&i| i as usize >= positions.len()) {
                return Err(ModelError::BadIndices { mesh: mesh.index() });
            }
            if mirrored {
                indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
            }
            let normals: Vec<Vec3> = match reader.read_normals() {
                Some(n) => n.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero()).collect(),
                None => face_normals(&positions, &indices),
            };
            let mut uvs: Vec<[f32; 2]> =
                reader.read_tex_coords(set).map(|t| t.into_f32().collect()).unwrap_or_default();
            uvs.resize(positions.len(), [0.0; 2]);
            let pivots = match primitive.get(&gltf::Semantic::Extras(PIVOT_ATTRIBUTE[1..].into())) {
                Some(accessor) => {
                    let data = |b: gltf::Buffer| buffers.get(b.index()).map(Vec::as_slice);
                    let pivots = read_pivots(accessor, positions.len(), data)
                        .ok_or(ModelError::BadPivots { mesh: mesh.index() })?;
                    pivots.into_iter().map(|p| world.transform_point3(p)).collect()
                }
                None => positions.clone(),
            };
            let attributes = positions.iter().zip(&normals).zip(&uvs).zip(&pivots);
            vertices.extend(attributes.map(|(((p, n), uv), pivot)| MeshVertex {
                position_model_m: p.to_array(),
                normal_model: n.to_array(),
                uv: *uv,
                pivot_model_m: pivot.to_array(),
            }));
            by_material[material].extend(indices.iter().map(|i| base + i));
        }
    }
    if by_material[default_material].is_empty() {
        by_material.pop();
    } else {
        materials.push(Material {
            name: "default".into(),
            base_color_factor: [1.0; 4],
            alpha_mode: AlphaMode::Opaque,
            alpha_cutoff: 0.5,
            double_sided: false,
            texture: None,
            detail: None,
        });
    }
    let mut indices = Vec::new();
    let mut submeshes = Vec::new();
    for (material, list) in by_material.iter().enumerate().filter(|(_, l)| !l.is_empty()) {
        let first_index = indices.len() as u32;
        indices.extend_from_slice(list);
        submeshes.push(Submesh { material: material as u32, first_index, index_count: list.len() as u32 });
    }
    if indices.is_empty() {
        return Err(ModelError::NoTriangles);
    }
    Ok(Mesh { vertices, indices, submeshes, materials })
}

/// A material's continuous LOD, from its `extras` (`{"terramp_detail": {...}}`); `None` when it
/// has none; what is wrong with it otherwise.
fn read_detail(extras: &gltf::json::Extras) -> Result<Option<Detail>, String> {
    let Some(raw) = extras else { return Ok(None) };
    let object: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(raw.get()).map_err(|e| e.to_string())?;
    let Some(value) = object.get(DETAIL_EXTRAS) else { return Ok(None) };
    let detail: Detail = serde_json::from_value(value.clone()).map_err(|e| e.to_string())?;
    let size_m = match detail {
        Detail::Leaves { size_m } => size_m,
        Detail::Stems { diameter_m } => diameter_m,
    };
    if !(size_m.is_finite() && size_m > 0.0) {
        return Err(format!("size {size_m} m is not a positive length"));
    }
    Ok(Some(detail))
}

/// A `_PIVOT` accessor's `count` points, if it holds that many float VEC3s inside its buffer.
fn read_pivots<'a, 's>(
    accessor: gltf::Accessor<'a>,
    count: usize,
    buffer_data: impl Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
) -> Option<Vec<Vec3>> {
    // What the reader assumes (`check_accessor`: float VEC3s, not sparse, not empty, inside its
    // view), and one point per vertex.
    if check_accessor(&accessor, &[(F32, Dimensions::Vec3)]).is_err() || accessor.count() != count {
        return None;
    }
    let points: Vec<Vec3> =
        gltf::accessor::Iter::<[f32; 3]>::new(accessor, buffer_data)?.map(Vec3::from).collect();
    (points.len() == count).then_some(points)
}

/// Whether the glTF crate's reader can read `accessor` without a panic: one of `formats`, not
/// sparse, not empty, with a stride of at least its elements' size, and all inside its view.
fn check_accessor(accessor: &gltf::Accessor, formats: &[(DataType, Dimensions)]) -> Result<(), String> {
    let format = (accessor.data_type(), accessor.dimensions());
    if !formats.contains(&format) {
        return Err(format!("{format:?} elements, where the baker reads {formats:?}"));
    }
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    let (count, size) = (accessor.count(), accessor.size());
    if count == 0 {
        return Err("no elements".into());
    }
    let Some(view) = accessor.view() else { return Ok(()) };
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!("a stride of {stride} bytes under its {size}-byte elements"));
    }
    let end = stride
        .checked_mul(count - 1)
        .and_then(|n| n.checked_add(accessor.offset()))
        .and_then(|n| n.checked_add(size));
    if end.is_none_or(|end| end > view.length()) {
        return Err(format!("{count} elements from byte {} run past its buffer view", accessor.offset()));
    }
    if view.offset().checked_add(view.length()).is_none() {
        return Err(format!(
            "its buffer view's end, {} + {} bytes, is past any buffer",
            view.offset(),
            view.length()
        ));
    }
    Ok(())
}

/// Area-weighted vertex normals of a triangle list.
fn face_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    normals.into_iter().map(Vec3::normalize_or_zero).collect()
}

/// An image as RGBA8 with a full mip chain.
fn decode_image(
    image: &gltf::Image,
    buffers: &[Vec<u8>],
    beside: &dyn Fn(&str) -> Result<Vec<u8>, ModelError>,
    alpha_cutoff: Option<f32>,
) -> Result<MipChain, ModelError> {
    let index = image.index();
    let view_error = |problem| ModelError::ImageView { image: index, problem };
    let bytes = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buffer = buffers.get(view.buffer().index()).ok_or_else(|| view_error("no such buffer"))?;
            let end = view
                .offset()
                .checked_add(view.length())
                .ok_or_else(|| view_error("view outside its buffer"))?;
            buffer.get(view.offset()..end).ok_or_else(|| view_error("view outside its buffer"))?.to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => beside(uri)?,
    };
    let rgba = image::load_from_memory(&bytes)
        .map_err(|source| ModelError::ImageDecode { image: index, source })?
        .into_rgba8();
    let size = [rgba.width(), rgba.height()];
    let mip_count = 32 - size[0].max(size[1]).leading_zeros();
    Ok(build_mip_chain(rgba.into_raw(), size, mip_count, alpha_cutoff, &[]))
}
