//! How it works: `terramp-data bake` turns glTF models into impostors (`terramp::impostor`). Per
//! model: read the mesh and materials (`model`); take its bounding sphere (centred at mid-height);
//! then per LOD fit the planes (`fit`: Décoret-style greedy density with the smallest ε that
//! lets that many planes cover the model), frame each plane (normal facing out of the model, "up"
//! along model +Y, extent = the triangles it draws), give all planes of the LOD one texel density
//! and shelf-pack their rectangles (`pack`), render every plane's triangles orthographically into
//! its rectangle on the GPU (`render`), read the atlas back and build its coverage-preserving mips
//! (`terramp::impostor::build_mip_chain`, per plane). The impostor is then saved atomically.
//!
//! Mips: an atlas of 2^k texels keeps k − 5 levels (at most 5: 1024 → 64 texels), so rectangles
//! aligned to 2^(mips−1) texels never share a box with a neighbour at any level.

mod fit;
mod model;
mod pack;
mod render;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::{Mat4, Vec3, Vec4};
use terramp::gpu::{AdapterChoice, Gpu};
use terramp::impostor::{BoundingSphere, Impostor, ImpostorLod, Mesh, Plane, build_mip_chain};

use fit::{FitParams, FittedPlane};
use render::{Baker, PlaneDraw, UploadedMesh};

/// Atlas texels below this alpha are not the model (the leaves' glTF cutoff).
pub const ALPHA_CUTOFF: f32 = 0.5;

#[derive(clap::Args)]
pub struct BakeArgs {
    /// A glTF model (.glb) to bake; repeat for several. The impostor is named after the file.
    #[arg(long = "model", required = true)]
    pub models: Vec<PathBuf>,
    /// The output folder: one sub-folder per model (replaced atomically).
    #[arg(long)]
    pub out: PathBuf,
    /// Planes of each LOD's billboard cloud, finest first.
    #[arg(long, value_delimiter = ',', default_values_t = [17, 8, 2])]
    pub planes: Vec<usize>,
    /// Width and height of each LOD's atlas in texels (a power of two, 64 to 8192).
    #[arg(long, default_value_t = 1024)]
    pub texels: u32,
}

pub fn run(args: &BakeArgs) -> Result<()> {
    if args.planes.is_empty() || args.planes.contains(&0) {
        bail!("--planes needs one or more plane counts, each at least 1");
    }
    if !args.texels.is_power_of_two() || !(64..=8192).contains(&args.texels) {
        bail!("--texels {} must be a power of two from 64 to 8192", args.texels);
    }
    // Read every model before opening the GPU: a missing or broken file fails at once, named.
    let mut models: Vec<(String, &Path, Mesh)> = Vec::new();
    for path in &args.models {
        if !path.is_file() {
            bail!("{}: no such model file", path.display());
        }
        let name = model_name(path)?;
        if models.iter().any(|(other, _, _)| *other == name) {
            bail!("two models are named {name:?}: each impostor is named after its file");
        }
        models.push((name, path, model::load(path)?));
    }
    let started = Instant::now();
    let gpu = Gpu::new(AdapterChoice::Auto)?;
    eprintln!("baking {} models on {}", models.len(), gpu.describe());
    let baker = Baker::new(&gpu);
    for (name, path, mesh) in models {
        let impostor = bake_model(&gpu, &baker, name, mesh, &args.planes, args.texels)
            .with_context(|| format!("baking {}", path.display()))?;
        let folder = terramp::impostor::save(&args.out, &impostor)?;
        eprintln!("  wrote {}", folder.display());
    }
    println!(
        "baked {} models into {} in {:.1} s",
        args.models.len(),
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn model_name(path: &Path) -> Result<String> {
    match path.file_stem().and_then(|s| s.to_str()) {
        Some(name) if !name.is_empty() && !name.starts_with('.') => Ok(name.to_owned()),
        _ => bail!("{}: cannot name an impostor after this file", path.display()),
    }
}

/// The mip count and rectangle alignment for an atlas of `texels`.
pub fn atlas_mips(texels: u32) -> (u32, u32) {
    let mips = texels.ilog2().saturating_sub(5).clamp(1, 5);
    (mips, 1 << (mips - 1))
}

/// Bakes `mesh` into the impostor `name` with one LOD per entry of `plane_counts`.
fn bake_model(
    gpu: &Gpu,
    baker: &Baker,
    name: String,
    mesh: Mesh,
    plane_counts: &[usize],
    texels: u32,
) -> Result<Impostor> {
    let bounding_sphere = BoundingSphere::enclosing(mesh.vertices.iter().map(|v| v.position_model_m));
    let triangles: Vec<[Vec3; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [0, 1, 2].map(|k| Vec3::from(mesh.vertices[t[k] as usize].position_model_m)))
        .collect();
    eprintln!(
        "{name}: {} triangles, {} materials, bounding radius {:.2} m",
        triangles.len(),
        mesh.materials.len(),
        bounding_sphere.radius_m
    );
    let uploaded = baker.upload(gpu, &mesh);
    let mut lods = Vec::new();
    for (l, &count) in plane_counts.iter().enumerate() {
        lods.push(bake_lod(
            gpu,
            baker,
            &mesh,
            &uploaded,
            &triangles,
            &bounding_sphere,
            count,
            texels,
            &name,
            l,
        )?);
    }
    Ok(Impostor { name, bounding_sphere, alpha_cutoff: ALPHA_CUTOFF, lods, mesh })
}

/// A fitted plane's frame and the extent of what it draws.
struct Frame {
    normal: Vec3,
    offset_m: f32,
    right: Vec3,
    up: Vec3,
    /// (min, max) of the drawn vertices along right, up and normal (from the plane).
    extent_m: [[f32; 2]; 3],
}

fn frame(plane: &FittedPlane, triangles: &[[Vec3; 3]], centre: Vec3) -> Frame {
    let (mut normal, mut offset_m) = (plane.normal.normalize(), plane.offset_m);
    // Face out of the model, so the front shows the outermost surface (up, for a plane through it).
    if offset_m - normal.dot(centre) < 0.0 {
        (normal, offset_m) = (-normal, -offset_m);
    }
    let reference = if normal.y.abs() < 0.99 { Vec3::Y } else { Vec3::NEG_Z };
    let up = (reference - reference.dot(normal) * normal).normalize();
    let right = up.cross(normal);
    let mut extent_m = [[f32::INFINITY, f32::NEG_INFINITY]; 3];
    for &t in &plane.triangles {
        for p in triangles[t as usize] {
            for (k, value) in [right.dot(p), up.dot(p), normal.dot(p) - offset_m].into_iter().enumerate() {
                extent_m[k] = [extent_m[k][0].min(value), extent_m[k][1].max(value)];
            }
        }
    }
    Frame { normal, offset_m, right, up, extent_m }
}

#[allow(clippy::too_many_arguments)]
fn bake_lod(
    gpu: &Gpu,
    baker: &Baker,
    mesh: &Mesh,
    uploaded: &UploadedMesh,
    triangles: &[[Vec3; 3]],
    sphere: &BoundingSphere,
    count: usize,
    texels: u32,
    name: &str,
    lod: usize,
) -> Result<ImpostorLod> {
    let started = Instant::now();
    let fit = fit::fit_planes(triangles, count, &FitParams::default())?;
    if fit.planes.len() != count {
        bail!("LOD {lod}: the model gives {} planes, not {count} (too few triangles?)", fit.planes.len());
    }
    let fitted_s = started.elapsed().as_secs_f64();
    let centre = Vec3::from(sphere.centre_model_m);
    let frames: Vec<Frame> = fit.planes.iter().map(|p| frame(p, triangles, centre)).collect();
    let sizes: Vec<[f32; 2]> =
        frames.iter().map(|f| [0, 1].map(|k| f.extent_m[k][1] - f.extent_m[k][0])).collect();
    let (mip_count, align) = atlas_mips(texels);
    let packing = pack::pack(&sizes, texels, align).with_context(|| {
        format!("LOD {lod}: {count} planes do not fit a {texels}-texel atlas: raise --texels")
    })?;
    let density = packing.texels_per_m;
    let mut planes = Vec::new();
    let mut draws = Vec::new();
    for ((frame, fitted), rect) in frames.iter().zip(&fit.planes).zip(&packing.rects) {
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
        draws.push(PlaneDraw { clip_from_model, rect: *rect, triangles: fitted.triangles.clone() });
    }
    let texels_level0 = baker.render_atlas(gpu, mesh, uploaded, &draws, texels)?;
    let atlas =
        build_mip_chain(texels_level0, [texels, texels], mip_count, Some(ALPHA_CUTOFF), &packing.rects);
    eprintln!(
        "  {name} LOD {lod}: {count} planes, ε = {:.2} m ({:.0} % of the radius), {:.1} % of the area within ε, \
         leftovers up to {:.2} m, {density:.0} texels/m; fit {fitted_s:.2} s, total {:.2} s",
        fit.epsilon_m,
        100.0 * fit.epsilon_m / sphere.radius_m,
        100.0 * fit.covered_fraction,
        fit.max_leftover_distance_m,
        started.elapsed().as_secs_f64()
    );
    Ok(ImpostorLod { epsilon_m: fit.epsilon_m, planes, atlas })
}
