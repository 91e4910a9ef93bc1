//! How it works: baking a dense land-cover class's forest sample for texcells (Decaudin & Neyret
//! 2004, § 4 and 7; the format is `crate::texcell`). The class's species are read from their glTF
//! models (`bake::model`), each measured for its crown's horizontal radius per metre of height;
//! `place` sets the class's trees over the sample's square by Poisson disk, at the class's density,
//! with the tiles' twin-edge rule. The slab, as thick as the tallest tree and a margin, is cut into
//! `slices` horizontal slices; each is rendered orthographically from above with its near and far
//! planes half a slice above and below its middle (`Baker::render_instances`: every tree whose
//! crown reaches into the square, with its copies across the square's wrap, so the sample tiles
//! seamlessly), at `supersample`² texels per texel, then box-filtered into premultiplied coverage.
//! The pyramid, mips and 3D texture follow (`texcell::pyramid`).
//!
//! The slices hold albedo (the models' base colour, unlit): the renderer lights them with the
//! same sun as the ground and the trees.

mod place;

use std::path::Path;

use glam::{Mat4, Vec3};

use super::BakeError;
use super::model;
use super::render::{Baker, Instances, RenderError, UploadedMesh};
use crate::classes::{Class, ClassTable};
use crate::gpu::Gpu;
use crate::impostor::{Mesh, TexelRect};
use crate::texcell::pyramid::{self, Layer};
use crate::texcell::tiling::REFERENCE_CELLS;
use crate::texcell::{ForestSample, SampleTree};
pub use place::{Grown, place};

/// How a forest sample is baked.
#[derive(Debug, Clone, PartialEq)]
pub struct ForestOptions {
    /// The ground cell's side, metres (the sample spans `REFERENCE_CELLS` of them).
    pub cell_m: f32,
    /// Texels along the sample's side in the finest slices (a power of two).
    pub texels: u32,
    /// Slices of the finest level (a power of two, 2^N).
    pub slices: u32,
    /// Samples per texel along each side when rendering, box-filtered into coverage.
    pub supersample: u32,
    /// The germ of the placement.
    pub seed: u32,
}

impl Default for ForestOptions {
    fn default() -> Self {
        Self { cell_m: 32.0, texels: 256, slices: 32, supersample: 2, seed: 1 }
    }
}

/// Trees closer than this share of the mean spacing (1 / √density) are refused.
const SPACING_SHARE: f32 = 0.6;
/// The slab's margin above the tallest tree.
const HEIGHT_MARGIN: f32 = 1.02;

/// A species' mesh, uploaded, with its crown radius per metre of height and its height.
struct Model {
    name: String,
    mesh: Mesh,
    uploaded: UploadedMesh,
    /// Model-space height (its top's y; the base is at 0).
    height_m: f32,
}

/// Bakes the forest sample of `class` of `table`, its species' models read from `models` (a
/// folder of `<model>.glb`), on `gpu`.
pub fn bake_forest(
    gpu: &Gpu,
    table: &ClassTable,
    class: &Class,
    models: &Path,
    options: &ForestOptions,
) -> Result<ForestSample, BakeError> {
    let bad = |what: String| BakeError::Forest { class: class.name.clone(), problem: what };
    if !options.texels.is_power_of_two() || !options.slices.is_power_of_two() || options.supersample == 0 {
        return Err(bad(format!(
            "texels {} and slices {} must be powers of two, supersample at least 1",
            options.texels, options.slices
        )));
    }
    let baker = Baker::new(gpu);
    let mut source = super::ModelSource::new(models);
    let mut models_read: Vec<Model> = Vec::new();
    let mut grown = Vec::new();
    if let Some(rule) = class.seeds.iter().find(|rule| table.species_index(&rule.species).is_none()) {
        return Err(bad(format!("no species {:?}", rule.species)));
    }
    // Every variant of each rule's species, sharing its density as pass 3's seeds do.
    let variants = class.seeds.iter().flat_map(|rule| {
        table.species.iter().filter(move |s| s.name == rule.species).map(move |s| (rule, s))
    });
    for (rule, species) in variants {
        if !models_read.iter().any(|m| m.name == species.model) {
            let path =
                source.file(&species.model)?.unwrap_or_else(|| models.join(format!("{}.glb", species.model)));
            let mesh = model::load(&path)
                .map_err(|e| BakeError::Model { path: path.clone(), source: Box::new(e) })?;
            let height_m = mesh.vertices.iter().map(|v| v.position_model_m[1]).fold(0.0f32, f32::max);
            let uploaded = baker.upload(gpu, &mesh);
            models_read.push(Model { name: species.model.clone(), mesh, uploaded, height_m });
        }
        let m = models_read.iter().find(|m| m.name == species.model).ok_or_else(|| bad("model".into()))?;
        let crown_m = m
            .mesh
            .vertices
            .iter()
            .map(|v| v.position_model_m[0].hypot(v.position_model_m[2]))
            .fold(0.0f32, f32::max);
        grown.push(Grown {
            model: species.model.clone(),
            per_km2: rule.per_km2 / species.variants as f32,
            height_m: species.height_m,
            crown_per_height: crown_m / m.height_m.max(1e-3),
        });
    }
    let per_m2 = class.seeds.iter().map(|r| r.per_km2).sum::<f32>() * 1e-6;
    if per_m2 <= 0.0 {
        return Err(bad("the class grows nothing".into()));
    }
    let spacing_m = SPACING_SHARE / per_m2.sqrt();
    let trees = place(&grown, options.cell_m, per_m2, spacing_m, options.seed ^ u32::from(class.code));
    let height_m = trees.iter().map(|t| t.height_m).fold(0.0f32, f32::max) * HEIGHT_MARGIN;
    if trees.is_empty() || height_m <= 0.0 {
        return Err(bad("no tree could be placed".into()));
    }
    let finest = render_slices(gpu, &baker, &models_read, &trees, height_m, options)
        .map_err(|e| bad(format!("rendering the slices: {e}")))?;
    let (slices, volume) = crate::texcell::sample_images(finest);
    Ok(ForestSample {
        class_code: class.code,
        class_name: class.name.clone(),
        cell_m: options.cell_m,
        height_m,
        trees,
        slices,
        volume,
    })
}

/// What `bake_forests` baked for one class.
#[derive(Debug, Clone, PartialEq)]
pub struct ForestReport {
    /// The class's code and name.
    pub class_code: u8,
    /// The class's name.
    pub class_name: String,
    /// Where the sample was written.
    pub dir: std::path::PathBuf,
    /// Trees placed in it.
    pub trees: usize,
    /// Seconds it took.
    pub seconds: f64,
}

/// Bakes the forest sample of every class of `table` marked `texcells` into `out`
/// (`texcell::save`), on `gpu` (one is opened when `None`), telling `progress` each class.
pub fn bake_forests(
    gpu: Option<&Gpu>,
    table: &ClassTable,
    models: &Path,
    out: &Path,
    options: &ForestOptions,
    progress: &mut dyn FnMut(&ForestReport),
) -> Result<Vec<ForestReport>, BakeError> {
    let opened;
    let gpu = match gpu {
        Some(gpu) => gpu,
        None => {
            opened = Gpu::new(crate::gpu::AdapterChoice::Auto)?;
            &opened
        }
    };
    let mut reports = Vec::new();
    for class in table.classes.iter().filter(|c| c.texcells) {
        let started = std::time::Instant::now();
        let sample = bake_forest(gpu, table, class, models, options)?;
        let dir = crate::texcell::save(out, &sample)
            .map_err(|e| BakeError::Forest { class: class.name.clone(), problem: e.to_string() })?;
        let report = ForestReport {
            class_code: class.code,
            class_name: class.name.clone(),
            dir,
            trees: sample.trees.len(),
            seconds: started.elapsed().as_secs_f64(),
        };
        progress(&report);
        reports.push(report);
    }
    Ok(reports)
}

/// The finest slices, bottom first, premultiplied.
fn render_slices(
    gpu: &Gpu,
    baker: &Baker,
    models: &[Model],
    trees: &[SampleTree],
    height_m: f32,
    options: &ForestOptions,
) -> Result<Vec<Layer>, RenderError> {
    let (n, ss, texels) = (options.slices, options.supersample, options.texels);
    let side_px = texels * ss;
    // The slices side by side, as many per row as keep the image square-ish.
    let columns = (n as f32).sqrt().ceil() as u32;
    let rows = n.div_ceil(columns);
    let size = [columns * side_px, rows * side_px];
    let side_m = REFERENCE_CELLS as f32 * options.cell_m;
    let slice_m = height_m / n as f32;
    let rect = |k: u32| TexelRect {
        x: (k % columns) * side_px,
        y: (k / columns) * side_px,
        width: side_px,
        height: side_px,
    };
    let batches: Vec<Instances> = models
        .iter()
        .map(|m| {
            let mut instances = Vec::new();
            for k in 0..n {
                // Orthographic from above: x and y over the square, the slice's top at depth 0.
                let (bottom, top) = (k as f32 * slice_m, (k + 1) as f32 * slice_m);
                let clip_from_world = Mat4::from_cols_array(&[
                    2.0 / side_m,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    2.0 / side_m,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0 / (top - bottom),
                    0.0,
                    -1.0,
                    -1.0,
                    top / (top - bottom),
                    1.0,
                ]);
                for t in trees.iter().filter(|t| t.model == m.name) {
                    // No crown reaches farther from its trunk than the tree is tall.
                    let reach_m = t.height_m;
                    for (ox, oy) in
                        [-1.0f32, 0.0, 1.0].into_iter().flat_map(|x| [-1.0f32, 0.0, 1.0].map(|y| (x, y)))
                    {
                        let at = Vec3::new(t.position_m[0] + ox * side_m, t.position_m[1] + oy * side_m, 0.0);
                        let reaches = |c: f32| c + reach_m > 0.0 && c - reach_m < side_m;
                        if reaches(at.x) && reaches(at.y) {
                            instances.push((clip_from_world * world_from_model(m, t, at), rect(k)));
                        }
                    }
                }
            }
            Instances { mesh: &m.mesh, uploaded: &m.uploaded, instances }
        })
        .collect();
    let image = baker.render_instances(gpu, &batches, size)?;
    // Each slice box-filtered from its supersamples, straight colour into premultiplied coverage.
    let texel = |x: u32, y: u32| -> [f32; 4] {
        let i = 4 * (y * size[0] + x) as usize;
        let a = f32::from(image[i + 3]) / 255.0;
        let c = |k: usize| pyramid::decode_srgb(image[i + k]) * a;
        [c(0), c(1), c(2), a]
    };
    Ok((0..n)
        .map(|k| {
            let r = rect(k);
            let layer = (0..texels)
                .flat_map(|y| (0..texels).map(move |x| (x, y)))
                .map(|(x, y)| {
                    let mut sum = [0.0f32; 4];
                    for (sx, sy) in (0..ss).flat_map(|sy| (0..ss).map(move |sx| (sx, sy))) {
                        let t = texel(r.x + x * ss + sx, r.y + y * ss + sy);
                        for c in 0..4 {
                            sum[c] += t[c];
                        }
                    }
                    sum.map(|v| v / (ss * ss) as f32)
                })
                .collect();
            Layer { side: texels, texels: layer }
        })
        .collect())
}

/// Model space (x, y up, z; base at 0) to the sample's space (x east, y north, z up) for tree `t`
/// standing at `at`: scaled to its height, turned by its angle.
fn world_from_model(m: &Model, t: &SampleTree, at: Vec3) -> Mat4 {
    let scale = t.height_m / m.height_m.max(1e-3);
    // The renderer's turn of model space into the world: (x, y, z) → (x, −z, y).
    let axes = Mat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]);
    Mat4::from_translation(at)
        * Mat4::from_rotation_z(t.angle_deg.to_radians())
        * Mat4::from_scale(Vec3::splat(scale))
        * axes
}
