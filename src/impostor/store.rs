//! How it works: `save` writes a model's folder under a hidden name beside its final place
//! (`.NAME.partial-PID`), then puts it in place (`crate::publish`), so `DIR/NAME` is never a
//! half-written impostor.
//! `load` reads the manifest's version alone first, then the manifest, every PNG (checking each
//! mip's size) and the mesh (checksummed), and checks the whole for consistency before handing it
//! out, so a draw pass never uploads a half-valid model.

use std::fs;
use std::path::{Path, PathBuf};

use super::manifest::{ImageEntry, LodEntry, Manifest, MaterialEntry, MeshEntry, SlicingEntry, VersionOnly};
use super::{
    FORMAT_VERSION, Impostor, ImpostorError, ImpostorLod, MANIFEST_FILE, MESH_FILE, Material, Mesh, MipChain,
    Slicing, mesh_file, mip_size,
};

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ImpostorError + '_ {
    move |source| ImpostorError::Io { path: path.to_owned(), source }
}

/// Writes `impostor` as `dir/<impostor.name>/`, replacing an earlier one; returns that folder.
pub fn save(dir: &Path, impostor: &Impostor) -> Result<PathBuf, ImpostorError> {
    check(impostor)?;
    let out = dir.join(&impostor.name);
    replace_folder(
        &out,
        |staging| write_all(staging, impostor),
        |path, source| ImpostorError::Io { path: path.to_owned(), source },
    )?;
    Ok(out)
}

/// Makes `out` the folder `fill` writes, atomically: `fill` writes into a hidden folder beside it
/// (`.NAME.partial-PID`, removed if `fill` fails), which then takes the place of the old `out` in
/// one step (`crate::publish`, which says when the name may be briefly empty), the old one removed
/// last, so `out` is never half-written. Hidden folders that killed runs left beside `out` are
/// swept first. `io` names a failing path.
pub fn replace_folder<E>(
    out: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
    io: impl Fn(&Path, std::io::Error) -> E,
) -> Result<(), E> {
    let staging = crate::publish::begin_staging(out).map_err(|(path, e)| io(&path, e))?;
    if let Err(e) = fill(&staging) {
        let _ = fs::remove_dir_all(&staging);
        return Err(e);
    }
    crate::publish::publish(&staging, out).map_err(|(path, e)| io(&path, e))
}

fn write_all(folder: &Path, impostor: &Impostor) -> Result<(), ImpostorError> {
    let mut lods = Vec::new();
    for (l, lod) in impostor.lods.iter().enumerate() {
        let atlas = write_chain(folder, &format!("lod{l}"), &lod.atlas)?;
        lods.push(LodEntry { epsilon_m: lod.epsilon_m, atlas, planes: lod.planes.clone() });
    }
    let slicing = match &impostor.slicing {
        Some(s) => Some(SlicingEntry {
            orientations: s.orientations,
            slices: s.slices,
            crown_triangles: s.crown_triangles,
            trunk_triangles: s.trunk_triangles,
            lod: LodEntry {
                epsilon_m: s.lod.epsilon_m,
                atlas: write_chain(folder, "slicing", &s.lod.atlas)?,
                planes: s.lod.planes.clone(),
            },
        }),
        None => None,
    };
    let mut materials = Vec::new();
    for (k, m) in impostor.mesh.materials.iter().enumerate() {
        let texture = match &m.texture {
            Some(chain) => Some(write_chain(folder, &format!("material{k}"), chain)?),
            None => None,
        };
        materials.push(MaterialEntry {
            name: m.name.clone(),
            base_color_factor: m.base_color_factor,
            alpha_mode: m.alpha_mode,
            alpha_cutoff: m.alpha_cutoff,
            double_sided: m.double_sided,
            texture,
            detail: m.detail,
        });
    }
    let mesh = &impostor.mesh;
    let mesh_path = folder.join(MESH_FILE);
    fs::write(&mesh_path, mesh_file::encode(&mesh.vertices, &mesh.indices)).map_err(io(&mesh_path))?;
    let manifest = Manifest {
        format_version: FORMAT_VERSION,
        name: impostor.name.clone(),
        alpha: "straight".into(),
        alpha_cutoff: impostor.alpha_cutoff,
        bounding_sphere: impostor.bounding_sphere,
        mesh: MeshEntry {
            file: MESH_FILE.into(),
            vertex_count: mesh.vertices.len() as u32,
            index_count: mesh.indices.len() as u32,
            submeshes: mesh.submeshes.clone(),
        },
        materials,
        lods,
        slicing,
    };
    let text = toml::to_string(&manifest).map_err(|e| ImpostorError::ManifestWrite(e.to_string()))?;
    let manifest_path = folder.join(MANIFEST_FILE);
    fs::write(&manifest_path, text).map_err(io(&manifest_path))
}

fn write_chain(folder: &Path, stem: &str, chain: &MipChain) -> Result<ImageEntry, ImpostorError> {
    let mut files = Vec::new();
    for (m, texels) in chain.levels.iter().enumerate() {
        let file = format!("{stem}_mip{m}.png");
        let path = folder.join(&file);
        let [w, h] = chain.level_size(m as u32);
        image::save_buffer_with_format(
            &path,
            texels,
            w,
            h,
            image::ExtendedColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(|source| ImpostorError::Image { path: path.clone(), source })?;
        files.push(file);
    }
    Ok(ImageEntry { size: chain.size, mip_count: chain.mip_count(), files })
}

/// Reads `dir/<model>/`, everything checked.
pub fn load(dir: &Path, model: &str) -> Result<Impostor, ImpostorError> {
    let folder = dir.join(model);
    let manifest_path = folder.join(MANIFEST_FILE);
    let text = fs::read_to_string(&manifest_path).map_err(io(&manifest_path))?;
    let bad_manifest =
        |source| ImpostorError::Manifest { path: manifest_path.clone(), source: Box::new(source) };
    let version: VersionOnly = toml::from_str(&text).map_err(bad_manifest)?;
    if version.format_version != FORMAT_VERSION {
        return Err(ImpostorError::Version {
            path: manifest_path,
            found: version.format_version,
            expected: FORMAT_VERSION,
        });
    }
    let manifest: Manifest = toml::from_str(&text).map_err(bad_manifest)?;
    let mut lods = Vec::new();
    for (l, lod) in manifest.lods.iter().enumerate() {
        let atlas = read_chain(&folder, &lod.atlas, &format!("lods[{l}].atlas"))?;
        lods.push(ImpostorLod { epsilon_m: lod.epsilon_m, planes: lod.planes.clone(), atlas });
    }
    let slicing = match &manifest.slicing {
        Some(s) => Some(Slicing {
            orientations: s.orientations,
            slices: s.slices,
            crown_triangles: s.crown_triangles,
            trunk_triangles: s.trunk_triangles,
            lod: ImpostorLod {
                epsilon_m: s.lod.epsilon_m,
                planes: s.lod.planes.clone(),
                atlas: read_chain(&folder, &s.lod.atlas, "slicing.lod.atlas")?,
            },
        }),
        None => None,
    };
    let mut materials = Vec::new();
    for (k, m) in manifest.materials.iter().enumerate() {
        let texture = match &m.texture {
            Some(entry) => Some(read_chain(&folder, entry, &format!("materials[{k}].texture"))?),
            None => None,
        };
        materials.push(Material {
            name: m.name.clone(),
            base_color_factor: m.base_color_factor,
            alpha_mode: m.alpha_mode,
            alpha_cutoff: m.alpha_cutoff,
            double_sided: m.double_sided,
            texture,
            detail: m.detail,
        });
    }
    let mesh_path = folder.join(&manifest.mesh.file);
    let bytes = fs::read(&mesh_path).map_err(io(&mesh_path))?;
    let (vertices, indices) = mesh_file::decode(&mesh_path, &bytes)?;
    if vertices.len() != manifest.mesh.vertex_count as usize
        || indices.len() != manifest.mesh.index_count as usize
    {
        return Err(ImpostorError::Invalid {
            path: mesh_path,
            reason: format!(
                "{} vertices and {} indices, the manifest says {} and {}",
                vertices.len(),
                indices.len(),
                manifest.mesh.vertex_count,
                manifest.mesh.index_count
            ),
        });
    }
    let impostor = Impostor {
        name: manifest.name,
        bounding_sphere: manifest.bounding_sphere,
        alpha_cutoff: manifest.alpha_cutoff,
        lods,
        slicing,
        mesh: Mesh { vertices, indices, submeshes: manifest.mesh.submeshes, materials },
    };
    check(&impostor)?;
    Ok(impostor)
}

/// The image the manifest's entry `what` lists, each mip checked against its size.
fn read_chain(folder: &Path, entry: &ImageEntry, what: &str) -> Result<MipChain, ImpostorError> {
    let invalid = |reason: String| ImpostorError::Invalid {
        path: folder.join(MANIFEST_FILE),
        reason: format!("{what}: {reason}"),
    };
    let [w, h] = entry.size;
    if w == 0 || h == 0 {
        return Err(invalid(format!("size {w} × {h}: an image is at least 1 × 1 texels")));
    }
    // Past the 1 × 1 level a mip is that texel again, which no texture holds (and at 32 mips, the
    // size's shift would overflow).
    let most = w.max(h).ilog2() + 1;
    if !(1..=most).contains(&entry.mip_count) {
        return Err(invalid(format!("{} mips, where a {w} × {h} image has 1 to {most}", entry.mip_count)));
    }
    if entry.files.len() != entry.mip_count as usize {
        return Err(invalid(format!("{} mip files listed for {} mips", entry.files.len(), entry.mip_count)));
    }
    let mut levels = Vec::new();
    for (m, file) in entry.files.iter().enumerate() {
        let path = folder.join(file);
        let image =
            image::open(&path).map_err(|source| ImpostorError::Image { path: path.clone(), source })?;
        let expected = mip_size(entry.size, m as u32);
        if [image.width(), image.height()] != expected {
            return Err(ImpostorError::Invalid {
                path,
                reason: format!(
                    "{}x{} texels, mip {m} of {:?} should be {expected:?}",
                    image.width(),
                    image.height(),
                    entry.size
                ),
            });
        }
        levels.push(image.into_rgba8().into_raw());
    }
    Ok(MipChain { size: entry.size, levels })
}

/// Whether `dir/model` holds an impostor this build reads (its manifest's format version), without
/// loading it.
pub fn is_current(dir: &Path, model: &str) -> bool {
    let Ok(text) = fs::read_to_string(dir.join(model).join(MANIFEST_FILE)) else { return false };
    toml::from_str::<VersionOnly>(&text).is_ok_and(|v| v.format_version == FORMAT_VERSION)
}

/// The models in `dir` (folders holding a manifest), sorted by name.
pub fn models(dir: &Path) -> Result<Vec<String>, ImpostorError> {
    let mut names = Vec::new();
    for entry in fs::read_dir(dir).map_err(io(dir))? {
        let entry = entry.map_err(io(dir))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !name.starts_with('.') && entry.path().join(MANIFEST_FILE).is_file() {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}

/// Everything a draw pass relies on: a sane name, image sizes, uv rectangles inside the atlas,
/// submeshes inside the index buffer with known materials, indices inside the vertex buffer.
fn check(impostor: &Impostor) -> Result<(), ImpostorError> {
    let fail = |reason: String| Err(ImpostorError::Inconsistent { name: impostor.name.clone(), reason });
    let name = &impostor.name;
    if name.is_empty() || name.starts_with('.') || name.contains(['/', '\\']) {
        return fail("a model name must be a plain, non-hidden file name".into());
    }
    let chain_ok = |chain: &MipChain| {
        !chain.levels.is_empty()
            && chain.levels.iter().enumerate().all(|(m, level)| {
                let [w, h] = mip_size(chain.size, m as u32);
                level.len() == 4 * w as usize * h as usize
            })
    };
    let slicing = impostor.slicing.as_ref().map(|s| ("the slicing".to_string(), &s.lod));
    let lods = impostor.lods.iter().enumerate().map(|(l, lod)| (format!("LOD {l}"), lod));
    for (what, lod) in lods.chain(slicing) {
        if !chain_ok(&lod.atlas) {
            return fail(format!("{what}: atlas levels do not match its size"));
        }
        let inside = |uv: [f32; 2]| uv.iter().all(|c| (0.0..=1.0).contains(c));
        if let Some(p) = lod.planes.iter().position(|p| !inside(p.uv_min) || !inside(p.uv_max)) {
            return fail(format!("{what}: plane {p}'s atlas rectangle leaves the atlas"));
        }
    }
    if let Some(s) = &impostor.slicing {
        let (planes, [o, n]) = (s.lod.planes.len(), [s.orientations, s.slices]);
        match o.checked_mul(n) {
            None => return fail(format!("the slicing's orientations × slices, {o} × {n}, overflows u32")),
            Some(product) if product as usize != planes => {
                return fail(format!("the slicing has {planes} slices, not {o} × {n}"));
            }
            Some(_) => {}
        }
    }
    let mesh = &impostor.mesh;
    for m in &mesh.materials {
        if m.texture.as_ref().is_some_and(|t| !chain_ok(t)) {
            return fail(format!("material {:?}: texture levels do not match its size", m.name));
        }
    }
    for s in &mesh.submeshes {
        let end = u64::from(s.first_index) + u64::from(s.index_count);
        if end > mesh.indices.len() as u64 || s.material as usize >= mesh.materials.len() {
            return fail(format!("submesh {s:?} leaves the index buffer or names no material"));
        }
    }
    if mesh.indices.iter().any(|&i| i as usize >= mesh.vertices.len()) {
        return fail("an index leaves the vertex buffer".into());
    }
    Ok(())
}
