//! `tree` and `preview`: generate a tree as glTF (the library's `terramp::tree`), and draw models
//! side by side on one scale (`terramp::bake::contact_sheet`) to look at what the baker sees.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};

#[derive(clap::Args)]
pub struct TreeArgs {
    /// The species: spruce, pine, birch, broadleaf or bush.
    #[arg(long)]
    species: String,
    /// Random seed: the same species, seed and health give the same file, byte for byte.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Health from 1 (healthy) to 0 (dead): moderate losses omit leaves, larger ones branches.
    #[arg(long, default_value_t = 1.0)]
    health: f32,
    /// The glTF binary to write (.glb).
    #[arg(long)]
    out: PathBuf,
}

pub fn tree(args: &TreeArgs) -> Result<()> {
    let started = Instant::now();
    let tree = terramp::tree::generate(&args.species, args.seed, args.health)?;
    let bytes = tree.to_glb();
    std::fs::write(&args.out, &bytes).with_context(|| format!("writing {}", args.out.display()))?;
    let mesh = &tree.mesh;
    println!(
        "{} seed {} health {:.2}: {:.1} m (bounding sphere {:.2} per metre), {:?} stems per level, {} leaves, {} bark + {} leaf triangles, \
         {} KiB in {:.2} s: {}",
        tree.species,
        tree.seed,
        tree.health,
        mesh.height_m,
        tree.radius_per_height(),
        mesh.stems_per_level,
        mesh.leaf_count,
        mesh.bark.triangles(),
        mesh.leaves.triangles(),
        bytes.len() / 1024,
        started.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}

#[derive(clap::Args)]
pub struct PreviewArgs {
    /// A glTF model (.glb); repeat for several, drawn left to right, top to bottom.
    #[arg(long = "model", required = true)]
    models: Vec<PathBuf>,
    /// Models per row.
    #[arg(long, default_value_t = 5)]
    columns: u32,
    /// Width and height of each model's cell, texels.
    #[arg(long, value_delimiter = ',', default_values_t = [256, 384])]
    cell: Vec<u32>,
    /// The PNG to write.
    #[arg(long)]
    out: PathBuf,
}

pub fn preview(args: &PreviewArgs) -> Result<()> {
    let &[width, height] = args.cell.as_slice() else {
        bail!("--cell {:?}: give a width and a height, e.g. --cell 256,384", args.cell);
    };
    if [width, height].iter().any(|c| !(16..=4096).contains(c)) {
        bail!("--cell {width},{height}: each side must be 16 to 4096 texels");
    }
    let meshes = args
        .models
        .iter()
        .map(|path| terramp::bake::load_model(path).with_context(|| format!("reading {}", path.display())))
        .collect::<Result<Vec<_>>>()?;
    let gpu = terramp::gpu::Gpu::new(terramp::gpu::AdapterChoice::default())?;
    let (rgba, size) = terramp::bake::contact_sheet(&gpu, &meshes, args.columns, [width, height])?;
    let image = image::RgbaImage::from_raw(size[0], size[1], rgba).context("the sheet's size")?;
    image.save(&args.out).with_context(|| format!("writing {}", args.out.display()))?;
    println!("{} models drawn into {} ({} × {})", meshes.len(), args.out.display(), size[0], size[1]);
    Ok(())
}
