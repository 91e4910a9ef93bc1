//! How it works: lays the species' impostors out for one upload. Every species contributes four
//! pieces of geometry to one vertex and one index buffer, one per draw LOD: its real mesh (LOD 0)
//! and its billboard clouds of 17, 8 and 2 planes (LODs 1 to 3). Each vertex names its material:
//! a mesh vertex its glTF material's (a base colour, maybe a texture, wrapped), a plane vertex its
//! cloud's atlas (clamped). Every texture (the three atlases of a species, its mesh's textures)
//! becomes one layer of a single texture array, so a draw never switches bindings: layers share
//! one size (the largest, capped at `MAX_LAYER_TEXELS`) and the mip count of the shortest atlas
//! chain (atlases stop where a mip would mix two planes; meshes are only drawn up close, so a few
//! mips suffice), each level resampled from the source level nearest its size.
//!
//! The templates give each (species, LOD) group its index range, and each group's cross-fade draw
//! (at `SEED_GROUPS + group`) the next LOD's range. A model baked without a mesh draws its
//! 17-plane cloud up close instead; a species without an impostor keeps zero-index templates.
//!
//! With slicings (`draw_seeds.slicings`), an impostor that carries them draws them as LOD 1: its
//! mesh's bark submeshes, then every slice, one piece (the shader keeps two slicings per view).
//!
//! With continuous LOD (`draw_seeds.continuous_lod`), a mesh whose materials say how they shed
//! detail (`impostor::Detail`, generated trees) also takes LOD 1's place: its 17-plane cloud is
//! not uploaded, LOD 0 has no cross-fade (the same geometry goes on), and where its leaves and
//! each level's stems lie in the index buffer is kept ([`MeshDetail`]), for each frame's range.

use std::collections::HashMap;
use std::ops::Range;

use crate::classes::{Species, SpeciesKind};
use crate::config::DrawSeedsSettings;
use crate::gpu::gpu_types::{SeedDrawArgs, SeedMaterial, SeedVertex};
use crate::gpu::layout::{
    MATERIAL_BARK, MATERIAL_LEAVES, MATERIAL_REPEAT, MATERIAL_SLICE, MATERIAL_STEMS, MATERIAL_TEXTURED,
    SEED_DRAWS, SEED_GROUPS, SEED_LODS,
};
use crate::impostor::{AlphaMode, Detail, Impostor, Material, Mesh, MipChain, Slicing, Submesh, mip_size};

use super::DrawSeedsError;

/// Largest edge of a texture-array layer: larger atlases and textures are resampled down to it
/// (a 1024² layer with mips is 5.6 MB; a species takes 3 to 5).
pub const MAX_LAYER_TEXELS: u32 = 1024;
/// Billboard-cloud LODs a species needs (draw LODs 1 to 3).
const CLOUD_LODS: usize = SEED_LODS as usize - 1;

/// Everything uploaded for the species.
pub struct SeedAssets {
    /// Every species' four LODs of geometry in one vertex buffer, positions in model space (metres).
    pub vertices: Vec<SeedVertex>,
    /// Triangle lists into `vertices`, relative to each piece's `base_vertex` (its template's).
    pub indices: Vec<u32>,
    /// `SEED_DRAWS` draws: the groups' own, then their cross-fades into the next LOD.
    pub templates: Vec<SeedDrawArgs>,
    /// The material table the vertices index: base colour, texture layer, alpha cut-out and LOD.
    pub materials: Vec<SeedMaterial>,
    /// 1 / each species' model height (top above base), per metre; 0 for species not drawn.
    pub inv_model_height_m: Vec<f32>,
    /// Each species' mesh (its LOD 0 template), `None` for one baked without.
    pub meshes: Vec<Option<SeedDrawArgs>>,
    /// Each species' mesh where it is drawn with continuous LOD, `None` elsewhere.
    pub details: Vec<Option<MeshDetail>>,
    /// Each layer's mips at the common size, in layer order.
    pub layers: Vec<Vec<Vec<u8>>>,
    /// Edge of every layer's level 0, texels (the largest source, at most `MAX_LAYER_TEXELS`).
    pub size: u32,
    /// Mip levels of every layer: the shortest atlas chain's, so no mip mixes two planes.
    pub mips: u32,
}

/// Where a mesh drawn with continuous LOD keeps its pieces, as absolute ranges of the index
/// buffer: what a frame narrows its draw to (`frame::detail_templates`).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshDetail {
    /// The whole mesh (its LOD 0 template).
    pub whole: SeedDrawArgs,
    /// The leaf quads, if they are laid out as the continuous LOD reads them.
    pub leaves: Option<LeafRun>,
    /// Each branching level's stems: its indices and mean diameter, model metres.
    pub stems: Vec<(Range<u32>, f32)>,
    /// The indices of what is drawn whole at any distance (materials without a detail).
    pub whole_pieces: Vec<Range<u32>>,
}

/// A run of leaf quads in the index buffer: six indices each, in the order they thin out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeafRun {
    /// The first leaf's first index.
    pub first_index: u32,
    /// Leaves in the run.
    pub count: u32,
    /// Their mean size, model metres.
    pub size_m: f32,
}

impl SeedAssets {
    /// One piece of geometry, its vertices already carrying their materials: appended, and its
    /// index range returned as a template.
    fn push(&mut self, vertices: impl IntoIterator<Item = SeedVertex>, indices: &[u32]) -> SeedDrawArgs {
        let template = SeedDrawArgs {
            index_count: indices.len() as u32,
            instance_count: 0,
            first_index: self.indices.len() as u32,
            base_vertex: self.vertices.len() as i32,
            first_instance: 0,
        };
        self.vertices.extend(vertices);
        self.indices.extend_from_slice(indices);
        template
    }

    /// A new layer from `chain`, resampled to the common size and mips.
    fn layer(&mut self, chain: &MipChain) -> u32 {
        let levels = (0..self.mips).map(|m| resample(chain, mip_size([self.size; 2], m))).collect();
        self.layers.push(levels);
        self.layers.len() as u32 - 1
    }

    fn material(&mut self, material: SeedMaterial) -> u32 {
        self.materials.push(material);
        self.materials.len() as u32 - 1
    }
}

/// What LOD 1 may be drawn with besides the 17-plane cloud (`[draw_seeds]`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LodChoices {
    /// Meshes that say how they shed detail take LOD 1's place (`draw_seeds.continuous_lod`).
    pub continuous_lod: bool,
    /// Impostors with slicings draw them as LOD 1, with this brightness correction
    /// (`draw_seeds.slicings`, `slicing_brightness`); `None`: clouds.
    pub slicing_brightness: Option<f32>,
    /// The species (a bit per species index) that may be drawn as slicings: plants, whose crowns
    /// are sparse; a rock is solid, and keeps its cloud.
    pub sliced_species: u32,
}

impl LodChoices {
    /// The choices `settings` make for `species`.
    pub fn of(settings: &DrawSeedsSettings, species: &[Species]) -> Self {
        let plants = species.iter().enumerate().filter(|(_, s)| s.kind != SpeciesKind::Rock);
        Self {
            continuous_lod: settings.continuous_lod,
            slicing_brightness: settings.slicings.then_some(settings.slicing_brightness as f32),
            sliced_species: plants.filter(|(i, _)| *i < 32).fold(0, |mask, (i, _)| mask | 1 << i),
        }
    }

    /// The slicing species `species` draws as LOD 1 with its brightness correction, if any.
    fn slicing_of<'a>(&self, species: usize, impostor: &'a Impostor) -> Option<(f32, &'a Slicing)> {
        let allowed = species < 32 && self.sliced_species & (1 << species) != 0;
        let brightness = self.slicing_brightness.filter(|_| allowed)?;
        Some((brightness, impostor.slicing.as_ref()?))
    }
}

/// Lays out `impostors` (by species index; `None`: not drawn), LOD 1 as `choices` says: the
/// meshes that say how they shed detail laid out for continuous LOD, or the slicings.
pub fn gather(impostors: &[Option<Impostor>], choices: LodChoices) -> Result<SeedAssets, DrawSeedsError> {
    let continuous = choices.continuous_lod;
    let species_max = (SEED_GROUPS / SEED_LODS) as usize;
    let present = || impostors.iter().take(species_max).flatten();
    for impostor in present() {
        if impostor.lods.len() < CLOUD_LODS {
            return Err(DrawSeedsError::TooFewLods {
                model: impostor.name.clone(),
                lods: impostor.lods.len(),
            });
        }
    }
    let atlases = || {
        let drawn = impostors.iter().enumerate().take(species_max);
        drawn.filter_map(|(species, i)| i.as_ref().map(|i| (species, i))).flat_map(move |(species, i)| {
            let slicing = choices.slicing_of(species, i).map(|(_, s)| &s.lod.atlas);
            i.lods[..CLOUD_LODS].iter().map(|l| &l.atlas).chain(slicing)
        })
    };
    let textures = || present().flat_map(|i| i.mesh.materials.iter().filter_map(|m| m.texture.as_ref()));
    let size = atlases().chain(textures()).map(|a| a.size[0].max(a.size[1])).max().unwrap_or(1);
    let size = size.clamp(1, MAX_LAYER_TEXELS);
    let mips = atlases().map(|a| a.mip_count()).min().unwrap_or(1).clamp(1, size.ilog2() + 1);
    let mut out = SeedAssets {
        vertices: Vec::new(),
        indices: Vec::new(),
        templates: vec![SeedDrawArgs::default(); SEED_DRAWS as usize],
        materials: Vec::new(),
        inv_model_height_m: vec![0.0; species_max],
        meshes: vec![None; species_max],
        details: vec![None; species_max],
        layers: Vec::new(),
        size,
        mips,
    };
    for (species, impostor) in impostors.iter().enumerate().take(species_max) {
        let Some(impostor) = impostor else { continue };
        out.inv_model_height_m[species] = 1.0 / model_height_m(impostor);
        let detailed = continuous && has_detail(impostor);
        let sliced = choices.slicing_of(species, impostor).filter(|_| !detailed);
        let mut lods = [SeedDrawArgs::default(); SEED_LODS as usize];
        for (k, level) in impostor.lods[..CLOUD_LODS].iter().enumerate() {
            if (detailed || sliced.is_some()) && k == 0 {
                // The mesh, or the slicings, take the 17-plane cloud's place.
                continue;
            }
            let layer = out.layer(&level.atlas);
            let material = out.material(SeedMaterial {
                base_colour: [1.0; 4],
                layer,
                alpha_cutoff: impostor.alpha_cutoff,
                lod: k as u32 + 1,
                flags: MATERIAL_TEXTURED,
                last_lod: k as u32 + 1,
                ..Default::default()
            });
            // A plane's texels are baked leaves: it bends with the plant, nothing flutters.
            let vertices = level.vertices().into_iter().map(|v| SeedVertex {
                position_model_m: v.position_model_m,
                normal_model: v.normal_model,
                uv: v.uv_atlas,
                material,
                pivot_model_m: v.position_model_m,
            });
            lods[k + 1] = out.push(vertices, &level.indices());
        }
        if let Some((brightness, slicing)) = sliced {
            lods[1] = push_slicing(&mut out, impostor, slicing, brightness);
        }
        if impostor.mesh.indices.is_empty() && sliced.is_none() {
            lods[0] = lods[1];
        } else {
            let detail = push_mesh(&mut out, impostor, detailed);
            lods[0] = detail.whole;
            out.meshes[species] = Some(detail.whole);
            if detailed {
                lods[1] = detail.whole;
                out.details[species] = Some(detail);
            }
        }
        let first = species * SEED_LODS as usize;
        out.templates[first..first + SEED_LODS as usize].copy_from_slice(&lods);
        // A group's cross-fade draws the next LOD; the last LOD fades out to nothing, and a mesh
        // that goes on as LOD 1 needs none.
        let fades = SEED_GROUPS as usize + first;
        out.templates[fades..fades + CLOUD_LODS].copy_from_slice(&lods[1..]);
        if detailed {
            out.templates[fades] = SeedDrawArgs::default();
        }
    }
    Ok(out)
}

/// Whether the impostor's mesh says how it sheds detail.
fn has_detail(impostor: &Impostor) -> bool {
    !impostor.mesh.indices.is_empty() && impostor.mesh.materials.iter().any(|m| m.detail.is_some())
}

/// The model's height: its mesh's top, or its sphere's (centred at mid-height) without a mesh.
fn model_height_m(impostor: &Impostor) -> f32 {
    let top = impostor.mesh.vertices.iter().map(|v| v.position_model_m[1]).fold(f32::MIN, f32::max);
    if top > 0.0 { top } else { (impostor.bounding_sphere.centre_model_m[1] * 2.0).max(1e-3) }
}

/// The mesh, one material per submesh (drawn as LODs 0 and 1 when `detailed`); a vertex two
/// submeshes share is repeated for each. Materials with the same texture share its layer.
fn push_mesh(out: &mut SeedAssets, impostor: &Impostor, detailed: bool) -> MeshDetail {
    let mesh = &impostor.mesh;
    let mut layers: HashMap<usize, u32> = HashMap::new();
    let mut vertices = Vec::new();
    let mut indices = Vec::with_capacity(mesh.indices.len());
    let (first_vertex, first_index) = (out.vertices.len() as u32, out.indices.len() as u32);
    let mut leaves = None;
    let mut stems = Vec::new();
    let mut whole_pieces = Vec::new();
    for submesh in &mesh.submeshes {
        let Some(source) = mesh.materials.get(submesh.material as usize) else { continue };
        let (submesh_vertex, submesh_index) = (vertices.len() as u32, indices.len() as u32);
        let lods = [0, u32::from(detailed)];
        let Some(material) = push_submesh(out, mesh, submesh, lods, &mut layers, &mut vertices, &mut indices)
        else {
            continue;
        };
        let (detail_flag, _) = detail_of(source);
        let run = first_index + submesh_index..first_index + indices.len() as u32;
        let m = &mut out.materials[material as usize];
        match source.detail {
            Some(Detail::Leaves { size_m }) => {
                let quads = &indices[submesh_index as usize..];
                match leaf_quads(quads, submesh_vertex, vertices.len() as u32) {
                    Some(count) if leaves.is_none() => {
                        m.flags |= detail_flag;
                        m.first_leaf_vertex = first_vertex + submesh_vertex;
                        m.leaf_count = count;
                        leaves = Some(LeafRun { first_index: run.start, count, size_m });
                    }
                    _ => whole_pieces.push(run),
                }
            }
            Some(Detail::Stems { diameter_m })
                if stems_named(&indices[submesh_index as usize..], &vertices) =>
            {
                m.flags |= detail_flag;
                stems.push((run, diameter_m));
            }
            Some(Detail::Stems { .. }) => whole_pieces.push(run),
            None => whole_pieces.push(run),
        }
    }
    let whole = out.push(vertices, &indices);
    MeshDetail { whole, leaves, stems, whole_pieces }
}

/// A mesh material's continuous-LOD flag and its detail size (leaf size or stem diameter, model
/// metres); (0, 0) for a material drawn whole.
fn detail_of(source: &Material) -> (u32, f32) {
    match source.detail {
        Some(Detail::Leaves { size_m }) => (MATERIAL_LEAVES, size_m),
        Some(Detail::Stems { diameter_m }) => (MATERIAL_STEMS, diameter_m),
        None => (0, 0.0),
    }
}

/// Appends `submesh` of `mesh` to `vertices` and `indices` (its vertices repeated for it, whole
/// triangles only) with a material of its own serving draw LODs `lods` (first, last); textures
/// share a layer through `layers`. `None` when the submesh names no material.
fn push_submesh(
    out: &mut SeedAssets,
    mesh: &Mesh,
    submesh: &Submesh,
    [lod, last_lod]: [u32; 2],
    layers: &mut HashMap<usize, u32>,
    vertices: &mut Vec<SeedVertex>,
    indices: &mut Vec<u32>,
) -> Option<u32> {
    let source = mesh.materials.get(submesh.material as usize)?;
    let layer = source.texture.as_ref().map(|chain| {
        let first_alike = mesh.materials.iter().position(|m| m.texture.as_ref() == Some(chain));
        *layers.entry(first_alike.unwrap_or(submesh.material as usize)).or_insert_with(|| out.layer(chain))
    });
    let alpha_cutoff = match source.alpha_mode {
        AlphaMode::Opaque => -1.0,
        // (The baker reads glTF's BLEND as MASK: seeds are not sorted.)
        AlphaMode::Mask => source.alpha_cutoff,
    };
    let material = out.material(SeedMaterial {
        base_colour: source.base_color_factor,
        layer: layer.unwrap_or(0),
        alpha_cutoff,
        lod,
        flags: layer.map_or(0, |_| MATERIAL_TEXTURED | MATERIAL_REPEAT)
            | if source.is_bark() { MATERIAL_BARK } else { 0 },
        last_lod,
        detail_m: detail_of(source).1,
        ..Default::default()
    });
    let mut remap: HashMap<u32, u32> = HashMap::new();
    let range = submesh.first_index as usize..(submesh.first_index + submesh.index_count) as usize;
    let first = indices.len();
    for &index in mesh.indices.get(range).unwrap_or_default() {
        let Some(v) = mesh.vertices.get(index as usize) else { continue };
        let local = *remap.entry(index).or_insert_with(|| {
            vertices.push(SeedVertex {
                position_model_m: v.position_model_m,
                normal_model: v.normal_model,
                uv: v.uv,
                material,
                pivot_model_m: v.pivot_model_m,
            });
            vertices.len() as u32 - 1
        });
        indices.push(local);
    }
    // A dropped out-of-range index would shift every later triangle: keep whole triangles.
    indices.truncate(indices.len() - (indices.len() - first) % 3);
    Some(material)
}

/// LOD 1 drawn as the crown's slicings (`draw_seeds.slicings`): the mesh's bark submeshes (the
/// trunk and limbs), then every slice, one piece. The shader keeps the two slicings nearest the
/// view (`MATERIAL_SLICE`).
fn push_slicing(
    out: &mut SeedAssets,
    impostor: &Impostor,
    slicing: &Slicing,
    brightness: f32,
) -> SeedDrawArgs {
    let mesh = &impostor.mesh;
    let (mut layers, mut vertices, mut indices) = (HashMap::new(), Vec::new(), Vec::new());
    let bark = |s: &&Submesh| mesh.materials.get(s.material as usize).is_some_and(Material::is_bark);
    for submesh in mesh.submeshes.iter().filter(bark) {
        push_submesh(out, mesh, submesh, [1, 1], &mut layers, &mut vertices, &mut indices);
    }
    let layer = out.layer(&slicing.lod.atlas);
    let material = out.material(SeedMaterial {
        base_colour: [1.0; 4],
        layer,
        alpha_cutoff: impostor.alpha_cutoff,
        lod: 1,
        flags: MATERIAL_TEXTURED | MATERIAL_SLICE,
        last_lod: 1,
        slicings: slicing.orientations,
        slicing_brightness: brightness,
        ..Default::default()
    });
    let base = vertices.len() as u32;
    vertices.extend(slicing.lod.vertices().into_iter().map(|v| SeedVertex {
        position_model_m: v.position_model_m,
        normal_model: v.normal_model,
        uv: v.uv_atlas,
        material,
        pivot_model_m: v.position_model_m,
    }));
    indices.extend(slicing.lod.indices().into_iter().map(|i| base + i));
    out.push(vertices, &indices)
}

/// Whether every triangle of `indices` lies on one stem: its three vertices share a pivot (the
/// stem's base, as the tree generator writes it), by which the shader draws or leaves out a stem
/// whole; if not, those stems are drawn whole.
fn stems_named(indices: &[u32], vertices: &[SeedVertex]) -> bool {
    indices.chunks_exact(3).all(|t| {
        let pivot = |i: u32| vertices.get(i as usize).map(|v| v.pivot_model_m.map(f32::to_bits));
        pivot(t[0]).is_some() && pivot(t[0]) == pivot(t[1]) && pivot(t[0]) == pivot(t[2])
    })
}

/// The quads in `indices` (of the vertices `first..end`) if they are leaves as the continuous LOD
/// reads them, quad i's six indices on vertices `first + 4 i` to `first + 4 i + 3`, which is
/// what the tree generator writes; `None` if not (those leaves are then drawn whole).
fn leaf_quads(indices: &[u32], first: u32, end: u32) -> Option<u32> {
    let count = indices.len() / 6;
    let laid_out = indices.len() == 6 * count
        && end - first == 4 * count as u32
        && indices.chunks_exact(6).enumerate().all(|(i, quad)| {
            let corner = first + 4 * i as u32;
            quad.iter().all(|&v| (corner..corner + 4).contains(&v))
        });
    laid_out.then_some(count as u32)
}

/// The level of `chain` nearest `to` texels (the first no larger, else the smallest), resampled
/// to `to`, nearest texel (a copy when the sizes agree).
fn resample(chain: &MipChain, to: [u32; 2]) -> Vec<u8> {
    let levels = chain.levels.len().max(1) as u32;
    let level = (0..levels)
        .find(|&m| {
            let s = chain.level_size(m);
            s[0] <= to[0] && s[1] <= to[1]
        })
        .unwrap_or(levels - 1);
    let from = chain.level_size(level);
    let texels = &chain.levels[level as usize];
    if from == to {
        return texels.clone();
    }
    let mut out = Vec::with_capacity((4 * to[0] * to[1]) as usize);
    for y in 0..to[1] {
        let sy = (u64::from(y) * u64::from(from[1]) / u64::from(to[1])) as usize;
        for x in 0..to[0] {
            let sx = (u64::from(x) * u64::from(from[0]) / u64::from(to[0])) as usize;
            let i = 4 * (sy * from[0] as usize + sx);
            out.extend_from_slice(&texels[i..i + 4]);
        }
    }
    out
}
