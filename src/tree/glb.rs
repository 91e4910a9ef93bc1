//! How it works: a small glTF 2.0 binary writer for what the generator makes: one mesh of
//! indexed triangle primitives (positions with their bounds, normals, texture coordinates, each
//! vertex's leaf pivot as the application attribute `_PIVOT`, u32 indices), each with a material
//! whose base colour is an embedded PNG (sampled with repeat and trilinear filtering; materials
//! with the same PNG share it), opaque or alpha-masked, one- or two-sided, with its continuous
//! LOD in its `extras` (`impostor::Detail`); one node, one scene. The JSON
//! chunk comes first, then the binary chunk holding every buffer view back to back, each 4-byte
//! aligned, as the specification requires; both chunks are padded to 4 bytes (JSON with spaces,
//! binary with zeros). `serde_json` orders object keys, so the same mesh is the same bytes.
//! The `gltf` crate reads the result back in the tests, and the baker reads it like any model.

use serde_json::{Value, json};

use super::mesh::Part;
use crate::impostor::detail::DETAIL_EXTRAS;
use crate::impostor::{Detail, PIVOT_ATTRIBUTE};

/// How a material's alpha is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Alpha {
    /// Alpha ignored.
    Opaque,
    /// Texels with alpha below the cutoff are cut away.
    Mask(f32),
}

/// One material: a name, its base-colour texture (PNG bytes), its alpha, whether it is two-sided.
pub struct Material<'a> {
    /// Shown by glTF viewers.
    pub name: String,
    /// The base-colour texture, PNG-encoded (sRGB).
    pub png: &'a [u8],
    /// Opaque or alpha-masked.
    pub alpha: Alpha,
    /// Drawn from both sides (leaf cards).
    pub double_sided: bool,
    /// How its primitives shed detail with distance, written to its `extras`.
    pub detail: Option<Detail>,
}

/// A glTF binary of one node whose mesh holds one primitive per (part, material) pair; empty
/// parts are left out (a dead tree has no leaves).
pub fn write(name: &str, primitives: &[(&Part, Material)]) -> Vec<u8> {
    let mut binary = Binary::default();
    let mut accessors = Vec::new();
    let mut materials = Vec::new();
    let mut images = Vec::new();
    let mut textures = Vec::new();
    let mut gltf_primitives = Vec::new();
    // Materials that share a PNG share its image and texture.
    let mut pngs: Vec<&[u8]> = Vec::new();
    for (part, material) in primitives.iter().filter(|(part, _)| !part.indices.is_empty()) {
        let index = materials.len();
        let texture = match pngs.iter().position(|&png| png == material.png) {
            Some(texture) => texture,
            None => {
                let image_view = binary.view(material.png, None);
                images.push(json!({ "bufferView": image_view, "mimeType": "image/png" }));
                textures.push(json!({ "sampler": 0, "source": pngs.len() }));
                pngs.push(material.png);
                pngs.len() - 1
            }
        };
        let mut gltf_material = json!({
            "name": material.name,
            "pbrMetallicRoughness": {
                "baseColorTexture": { "index": texture },
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0
            },
            "doubleSided": material.double_sided,
        });
        if let Alpha::Mask(cutoff) = material.alpha {
            gltf_material["alphaMode"] = json!("MASK");
            gltf_material["alphaCutoff"] = json!(cutoff);
        }
        if let Some(detail) = material.detail {
            gltf_material["extras"] = json!({ DETAIL_EXTRAS: detail });
        }
        materials.push(gltf_material);

        let (min, max) = bounds(&part.positions);
        let mut accessor =
            |bytes: &[u8], target: u32, count: usize, kind: &str, component: u32, extra: Value| {
                let view = binary.view(bytes, Some(target));
                let mut a =
                    json!({ "bufferView": view, "componentType": component, "count": count, "type": kind });
                if let (Value::Object(a), Value::Object(extra)) = (&mut a, extra) {
                    a.extend(extra);
                }
                accessors.push(a);
                accessors.len() - 1
            };
        const ARRAY_BUFFER: u32 = 34962;
        const ELEMENT_ARRAY_BUFFER: u32 = 34963;
        const FLOAT: u32 = 5126;
        const UNSIGNED_INT: u32 = 5125;
        let n = part.positions.len();
        let position = accessor(
            bytemuck::cast_slice(&part.positions),
            ARRAY_BUFFER,
            n,
            "VEC3",
            FLOAT,
            json!({ "min": min, "max": max }),
        );
        let normal = accessor(bytemuck::cast_slice(&part.normals), ARRAY_BUFFER, n, "VEC3", FLOAT, json!({}));
        let uv = accessor(bytemuck::cast_slice(&part.uvs), ARRAY_BUFFER, n, "VEC2", FLOAT, json!({}));
        let pivot = accessor(bytemuck::cast_slice(&part.pivots), ARRAY_BUFFER, n, "VEC3", FLOAT, json!({}));
        let indices = accessor(
            bytemuck::cast_slice(&part.indices),
            ELEMENT_ARRAY_BUFFER,
            part.indices.len(),
            "SCALAR",
            UNSIGNED_INT,
            json!({}),
        );
        let mut attributes = json!({ "POSITION": position, "NORMAL": normal, "TEXCOORD_0": uv });
        attributes[PIVOT_ATTRIBUTE] = json!(pivot);
        gltf_primitives.push(json!({
            "attributes": attributes,
            "indices": indices,
            "material": index,
            "mode": 4,
        }));
    }
    let document = json!({
        "asset": { "version": "2.0", "generator": concat!("terramp ", env!("CARGO_PKG_VERSION"), " tree generator") },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0, "name": name }],
        "meshes": [{ "name": name, "primitives": gltf_primitives }],
        "materials": materials,
        "textures": textures,
        "images": images,
        // Linear magnification, trilinear minification, repeat in both directions.
        "samplers": [{ "magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497 }],
        "accessors": accessors,
        "bufferViews": binary.views,
        "buffers": [{ "byteLength": binary.bytes.len() }],
    });
    container(document.to_string().into_bytes(), binary.bytes)
}

/// The binary chunk as it is filled, and its buffer views.
#[derive(Default)]
struct Binary {
    bytes: Vec<u8>,
    views: Vec<Value>,
}

impl Binary {
    /// Appends `data` as a new buffer view (4-byte aligned); its index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": data.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        self.views.push(view);
        self.views.len() - 1
    }
}

fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
        (std::array::from_fn(|i| lo[i].min(p[i])), std::array::from_fn(|i| hi[i].max(p[i])))
    })
}

/// The 12-byte header, the JSON chunk padded with spaces, the binary chunk padded with zeros.
fn container(mut json: Vec<u8>, mut binary: Vec<u8>) -> Vec<u8> {
    json.resize(json.len().next_multiple_of(4), b' ');
    binary.resize(binary.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + binary.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(binary.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&binary);
    out
}
