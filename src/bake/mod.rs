//! How it works: [`bake_models`] (behind `terramp-data bake`, and the demo's first run) turns glTF
//! models into impostors ([`crate::impostor`]). Every model is read before the GPU is touched, so
//! a missing or broken file fails at once, named. Per model: read the mesh and materials
//! (`model`); take its bounding sphere (centred at mid-height); then per LOD fit the planes
//! (`fit`: Décoret-style greedy density with the smallest ε that lets that many planes cover the
//! model), frame each plane (normal facing out of the model, "up" along model +Y, extent = the
//! triangles it draws), give all planes of the LOD one texel density and shelf-pack their
//! rectangles (`pack`), render every plane's triangles orthographically into its rectangle on the
//! GPU (`render`), read the atlas back and build its coverage-preserving mips
//! ([`build_mip_chain`](crate::impostor::mips::build_mip_chain), per plane). The impostor is
//! then saved atomically.
//!
//! Mips: an atlas of 2^k texels keeps k − 5 levels (at most 5: 1024 → 64 texels), so rectangles
//! aligned to 2^(mips−1) texels never share a box with a neighbour at any level.

mod fit;
pub mod forest;
mod generated;
mod model;
mod pack;
mod planes;
mod render;
mod sheet;
mod slicing;

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;
use thiserror::Error;

use crate::gpu::{AdapterChoice, Gpu, GpuError};
use crate::impostor::{BoundingSphere, Impostor, ImpostorError, ImpostorLod, Mesh};
pub use fit::FitError;
use fit::FitParams;
pub use generated::ModelSource;
pub use model::{ModelError, load as load_model};
use planes::Frame;
pub use render::RenderError;
use render::{Baker, UploadedMesh};
pub use sheet::contact_sheet;
pub use slicing::SlicingOptions;

/// Atlas texels below this alpha are not the model (the leaves' glTF cutoff).
pub const ALPHA_CUTOFF: f32 = 0.5;

/// What to bake: one LOD per plane count, each with a square atlas of `texels`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BakeOptions {
    /// Planes of each LOD's billboard cloud, finest first.
    pub planes: Vec<usize>,
    /// Width and height of each LOD's atlas in texels (a power of two, 64 to 8192).
    pub texels: u32,
    /// The crown's slicings (Jakulin 2000), on an atlas of `texels` too; `None`: none baked.
    pub slicing: Option<SlicingOptions>,
}

/// Most slicings, and most slices per slicing, a bake may ask for.
pub const MAX_SLICING: u32 = 32;

impl Default for BakeOptions {
    fn default() -> Self {
        Self { planes: vec![17, 8, 2], texels: 1024, slicing: None }
    }
}

impl BakeOptions {
    /// Checks the plane counts (at least one, none 0) and the atlas size.
    pub fn validate(&self) -> Result<(), BakeError> {
        if self.planes.is_empty() || self.planes.contains(&0) {
            return Err(BakeError::Planes(self.planes.clone()));
        }
        if !self.texels.is_power_of_two() || !(64..=8192).contains(&self.texels) {
            return Err(BakeError::Texels(self.texels));
        }
        if let Some(s) = self.slicing
            && !((1..=MAX_SLICING).contains(&s.orientations) && (1..=MAX_SLICING).contains(&s.slices))
        {
            return Err(BakeError::Slicing(s));
        }
        Ok(())
    }
}

/// One baked model.
#[derive(Debug, Clone, PartialEq)]
pub struct BakeReport {
    /// The impostor's name: its model's file name without the extension.
    pub name: String,
    /// The impostor's folder (`out/<name>`).
    pub folder: PathBuf,
    /// Triangles of the model's mesh: every triangle primitive of its scene.
    pub triangles: usize,
    /// Wall-clock time to bake and save this model, in seconds (reading it not included).
    pub seconds: f64,
}

/// Why baking stopped; each names the option or the model file at fault.
#[derive(Debug, Error)]
pub enum BakeError {
    /// [`BakeOptions::planes`] is empty or holds a 0; holds the list given.
    #[error("planes {0:?}: baking needs one or more plane counts (one per LOD), each at least 1")]
    Planes(Vec<usize>),
    /// [`BakeOptions::texels`] is not a power of two from 64 to 8192; holds the value given.
    #[error("texels {0}: an atlas must be a power of two from 64 to 8192 texels wide")]
    Texels(u32),
    /// [`BakeOptions::slicing`] asks for no slicing or slice, or more than `MAX_SLICING`.
    #[error("slicings {0:?}: 1 to 32 slicings of 1 to 32 slices each")]
    Slicing(SlicingOptions),
    /// A model path is not a file; holds the path.
    #[error("{0}: no such model file")]
    NoSuchModel(PathBuf),
    /// A model file's stem is empty, hidden (starts with `.`) or not UTF-8, so it cannot name an
    /// impostor's folder; holds the path.
    #[error("{0}: cannot name an impostor after this file")]
    Unnamed(PathBuf),
    /// Two model files share a stem, so their impostors would share a folder; holds the name.
    #[error("two models are named {0:?}: each impostor is named after its file")]
    SameName(String),
    // Boxed, as `Lod`'s: the rarely built large errors keep every `Result` small.
    /// A model file could not be read as a glTF mesh (found before any GPU work).
    #[error("{path}: {source}")]
    Model {
        /// The model file.
        path: PathBuf,
        /// What is wrong with it.
        source: Box<ModelError>,
    },
    /// A class's forest sample (texcells) could not be baked.
    #[error("forest sample of class {class:?}: {problem}")]
    Forest {
        /// The land-cover class's name.
        class: String,
        /// What went wrong.
        problem: String,
    },
    /// A generated tree a name asks for (`tree::ModelName`) could not be made.
    #[error("generated tree {name}: {problem}")]
    Generated {
        /// The model name.
        name: String,
        /// What went wrong.
        problem: String,
    },
    /// No GPU could be opened to bake on (only tried when none is passed in).
    #[error("opening a GPU to bake on: {0}")]
    Gpu(#[from] GpuError),
    /// One LOD of a model could not be fitted, packed or rendered.
    #[error("baking {path}: LOD {lod}: {source}")]
    Lod {
        /// The model file.
        path: PathBuf,
        /// The LOD's index, 0 the finest: its place in [`BakeOptions::planes`]; one past the
        /// last for the slicings.
        lod: usize,
        /// What went wrong with it.
        source: Box<LodError>,
    },
    /// The baked impostor could not be written to its folder.
    #[error("saving the impostor of {path}: {source}")]
    Save {
        /// The model file it was baked from.
        path: PathBuf,
        /// The impostor store's error.
        source: ImpostorError,
    },
}

/// Why one LOD of a model could not be baked.
#[derive(Debug, Error)]
pub enum LodError {
    /// No planes could be fitted to the model's triangles.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The fit gave another number of planes than the LOD asks for.
    #[error("the model gives {found} planes, not {wanted} (too few triangles?)")]
    PlaneCount {
        /// Planes the fit gave.
        found: usize,
        /// Planes the LOD asks for: its entry of [`BakeOptions::planes`].
        wanted: usize,
    },
    /// The planes' rectangles do not fit the atlas even at the smallest texel density, one
    /// aligned cell each.
    #[error("{planes} planes do not fit a {texels}-texel atlas: raise the atlas size (texels)")]
    Pack {
        /// Planes of the LOD.
        planes: usize,
        /// The atlas's width and height in texels ([`BakeOptions::texels`]).
        texels: u32,
    },
    /// The atlas could not be rendered on the GPU.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// Bakes every model of `models` into `out/<name>/` (each folder replaced atomically), named after
/// its file, on `gpu` or, when `None`, on an adapter of its own (`AdapterChoice::Auto`, opened
/// only once every model has been read). `progress` reports each model and LOD on stderr.
pub fn bake_models(
    gpu: Option<&Gpu>,
    models: &[PathBuf],
    out: &Path,
    options: &BakeOptions,
    progress: bool,
) -> Result<Vec<BakeReport>, BakeError> {
    options.validate()?;
    // Name every model, then read them all, before opening the GPU: a missing, misnamed or broken
    // file fails at once, named, and the cheap checks come before the slow reads.
    let mut names: Vec<String> = Vec::new();
    for path in models {
        if !path.is_file() {
            return Err(BakeError::NoSuchModel(path.clone()));
        }
        let name = model_name(path)?;
        if names.contains(&name) {
            return Err(BakeError::SameName(name));
        }
        names.push(name);
    }
    let mut meshes: Vec<(String, &Path, Mesh)> = Vec::new();
    for (name, path) in names.into_iter().zip(models) {
        let mesh = model::load(path)
            .map_err(|source| BakeError::Model { path: path.clone(), source: Box::new(source) })?;
        meshes.push((name, path, mesh));
    }
    if meshes.is_empty() {
        return Ok(Vec::new());
    }
    let own;
    let gpu = match gpu {
        Some(gpu) => gpu,
        None => {
            own = Gpu::new(AdapterChoice::Auto)?;
            &own
        }
    };
    if progress {
        eprintln!("baking {} models on {}", meshes.len(), gpu.describe());
    }
    let baker = Baker::new(gpu);
    let mut reports = Vec::new();
    for (name, path, mesh) in meshes {
        let started = Instant::now();
        let triangles = mesh.indices.len() / 3;
        let impostor = bake_model(gpu, &baker, name, mesh, options, progress).map_err(|(lod, source)| {
            BakeError::Lod { path: path.to_owned(), lod, source: Box::new(source) }
        })?;
        let folder = crate::impostor::save(out, &impostor)
            .map_err(|source| BakeError::Save { path: path.to_owned(), source })?;
        if progress {
            eprintln!("  wrote {}", folder.display());
        }
        let seconds = started.elapsed().as_secs_f64();
        reports.push(BakeReport { name: impostor.name, folder, triangles, seconds });
    }
    Ok(reports)
}

/// What [`bake_missing`] did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Missing {
    /// The impostors it baked.
    pub baked: Vec<BakeReport>,
    /// Model files it needed and could not find: their impostors are still missing.
    pub absent: Vec<PathBuf>,
}

/// Bakes into `out` each of `names` (model file stems) whose impostor is missing there or of
/// another format ([`crate::impostor::is_current`]), from `models/<name>.glb` or, for a
/// generated tree's name, the generator ([`ModelSource`]); the others are left as they are.
/// Names without a model are reported, not an error. The GPU is `gpu`, or when `None` one opened
/// as [`bake_models`] opens it, only if something is to be baked.
pub fn bake_missing(
    gpu: Option<&Gpu>,
    models: &Path,
    names: &[&str],
    out: &Path,
    options: &BakeOptions,
    progress: bool,
) -> Result<Missing, BakeError> {
    let mut names: Vec<&str> =
        names.iter().copied().filter(|n| !crate::impostor::is_current(out, n)).collect();
    names.sort_unstable();
    names.dedup();
    let mut source = ModelSource::new(models);
    let (mut found, mut absent) = (Vec::new(), Vec::new());
    for name in names {
        match source.file(name)? {
            Some(file) => found.push(file),
            None => absent.push(models.join(format!("{name}.glb"))),
        }
    }
    let baked = if found.is_empty() { Vec::new() } else { bake_models(gpu, &found, out, options, progress)? };
    Ok(Missing { baked, absent })
}

fn model_name(path: &Path) -> Result<String, BakeError> {
    match path.file_stem().and_then(|s| s.to_str()) {
        Some(name) if !name.is_empty() && !name.starts_with('.') => Ok(name.to_owned()),
        _ => Err(BakeError::Unnamed(path.to_owned())),
    }
}

/// The mip count and rectangle alignment for an atlas of `texels`.
fn atlas_mips(texels: u32) -> (u32, u32) {
    let mips = texels.ilog2().saturating_sub(5).clamp(1, 5);
    (mips, 1 << (mips - 1))
}

/// A model being baked: what every LOD draws from.
struct Job<'a> {
    gpu: &'a Gpu,
    baker: &'a Baker,
    name: &'a str,
    mesh: &'a Mesh,
    uploaded: &'a UploadedMesh,
    triangles: &'a [[Vec3; 3]],
    sphere: &'a BoundingSphere,
    progress: bool,
}

/// Bakes `mesh` into the impostor `name` with one LOD per plane count of `options`; an error
/// comes with the LOD it stopped at.
fn bake_model(
    gpu: &Gpu,
    baker: &Baker,
    name: String,
    mesh: Mesh,
    options: &BakeOptions,
    progress: bool,
) -> Result<Impostor, (usize, LodError)> {
    let bounding_sphere = BoundingSphere::enclosing(mesh.vertices.iter().map(|v| v.position_model_m));
    let triangles: Vec<[Vec3; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [0, 1, 2].map(|k| Vec3::from(mesh.vertices[t[k] as usize].position_model_m)))
        .collect();
    if progress {
        eprintln!(
            "{name}: {} triangles, {} materials, bounding radius {:.2} m",
            triangles.len(),
            mesh.materials.len(),
            bounding_sphere.radius_m
        );
    }
    let uploaded = baker.upload(gpu, &mesh);
    let job = Job {
        gpu,
        baker,
        name: &name,
        mesh: &mesh,
        uploaded: &uploaded,
        triangles: &triangles,
        sphere: &bounding_sphere,
        progress,
    };
    let mut lods = Vec::new();
    for (l, &count) in options.planes.iter().enumerate() {
        lods.push(bake_lod(&job, count, options.texels, l).map_err(|e| (l, e))?);
    }
    let slicing = match options.slicing {
        Some(slicing_options) => {
            let started = Instant::now();
            let slicing = slicing::bake(&job, slicing_options, options.texels)
                .map_err(|e| (options.planes.len(), e))?;
            if progress {
                match &slicing {
                    Some(s) => eprintln!(
                        "  {name} slicings: {} × {} slices, ε = {:.2} m; crown {} triangles, trunk and limbs {} \
                         left to the mesh; {:.2} s",
                        s.orientations,
                        s.slices,
                        s.lod.epsilon_m,
                        s.crown_triangles,
                        s.trunk_triangles,
                        started.elapsed().as_secs_f64()
                    ),
                    None => eprintln!("  {name} slicings: none, no crown (all bark): drawn as its mesh"),
                }
            }
            slicing
        }
        None => None,
    };
    Ok(Impostor { name, bounding_sphere, alpha_cutoff: ALPHA_CUTOFF, lods, slicing, mesh })
}

/// LOD `lod` of `job`'s model: `count` planes on an atlas of `texels`.
fn bake_lod(job: &Job, count: usize, texels: u32, lod: usize) -> Result<ImpostorLod, LodError> {
    let started = Instant::now();
    let fit = fit::fit_planes(job.triangles, count, &FitParams::default())?;
    if fit.planes.len() != count {
        return Err(LodError::PlaneCount { found: fit.planes.len(), wanted: count });
    }
    let fitted_s = started.elapsed().as_secs_f64();
    let centre = Vec3::from(job.sphere.centre_model_m);
    let frames: Vec<Frame> = fit.planes.iter().map(|p| Frame::fitted(p, job.triangles, centre)).collect();
    let baked = planes::bake(job, &frames, texels)?;
    if job.progress {
        eprintln!(
            "  {} LOD {lod}: {count} planes, ε = {:.2} m ({:.0} % of the radius), \
             {:.1} % of the area within ε, leftovers up to {:.2} m, {:.0} texels/m; fit {fitted_s:.2} s, total {:.2} s",
            job.name,
            fit.epsilon_m,
            100.0 * fit.epsilon_m / job.sphere.radius_m,
            100.0 * fit.covered_fraction,
            fit.max_leftover_distance_m,
            baked.texels_per_m,
            started.elapsed().as_secs_f64()
        );
    }
    Ok(ImpostorLod { epsilon_m: fit.epsilon_m, planes: baked.planes, atlas: baked.atlas })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_need_plane_counts_and_a_power_of_two_atlas() {
        assert!(BakeOptions::default().validate().is_ok());
        let with = |planes: Vec<usize>, texels| BakeOptions { planes, texels, slicing: None }.validate();
        assert!(matches!(with(vec![], 1024), Err(BakeError::Planes(_))));
        assert!(matches!(with(vec![4, 0], 1024), Err(BakeError::Planes(_))));
        for texels in [0, 32, 1000, 16384] {
            assert!(matches!(with(vec![2], texels), Err(BakeError::Texels(t)) if t == texels));
        }
        assert!(with(vec![1], 64).is_ok() && with(vec![1], 8192).is_ok());
        let sliced = |orientations, slices| BakeOptions {
            slicing: Some(SlicingOptions { orientations, slices }),
            ..BakeOptions::default()
        };
        assert!(sliced(6, 5).validate().is_ok());
        for (o, s) in [(0, 5), (6, 0), (33, 5), (6, 33)] {
            assert!(matches!(sliced(o, s).validate(), Err(BakeError::Slicing(_))), "{o} × {s}");
        }
    }

    #[test]
    fn missing_models_fail_before_any_gpu_work() {
        let missing = PathBuf::from("no/such/Nothing.glb");
        let err = bake_models(None, &[missing], Path::new("unused"), &BakeOptions::default(), false);
        assert!(matches!(&err, Err(BakeError::NoSuchModel(p)) if p.ends_with("Nothing.glb")), "{err:?}");
    }
}
