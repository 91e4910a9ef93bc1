//! How it works: `terramp-data build` turns GeoTIFF inputs into a dataset folder.
//!
//! Every input is opened and checked first (`raster`), so a bad file fails before any work. The
//! DEM then fixes the frame (`frame`): its projected CRS and grid, or a local metric frame for a
//! DEM in degrees. Each layer is a `GridRaster` (the source as seen on the layer's grid, read
//! directly when aligned, else warped by GDAL) and is written tile by tile by the library's
//! `write_layer` into a staging folder: heights after a scan that finds their range and voids
//! (`heights`, `fill`), then imagery (`imagery`) and land cover (`landcover`, after a scan that
//! finds its codes, hence its LCC palette). The manifest is written last and the folder published
//! atomically, so `--out` never holds half a dataset.

mod earth;
mod fill;
mod frame;
mod gdal_ffi;
mod heights;
mod imagery;
mod landcover;
pub mod parts;
mod raster;
mod spill;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use terramp::dataset::block_encode::encode_staged_imagery;
use terramp::dataset::{FORMAT_VERSION, ImageryFormat, Manifest, Staging};

use frame::{Frame, Grid};
use heights::{Footprint, HeightScan, HeightStep};
use imagery::{Imagery, ImageryLook};
use landcover::{Landcover, LandcoverScan};
use raster::{Access, GridRaster, Resampling, SourceRaster};
use spill::SpilledGrid;

/// GDAL's raster block cache: enough for a few rows of tiles, and a bound on resident memory.
const GDAL_BLOCK_CACHE_BYTES: i64 = 64 << 20;

/// What a dataset is built from, for `build` and `plan` alike.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct InputArgs {
    /// The DEM: heights in metres, in a projected CRS or in geographic degrees.
    #[arg(long)]
    pub dem: Option<PathBuf>,
    /// Imagery to drape over the terrain (any CRS; reprojected onto the DEM's extent).
    #[arg(long)]
    pub imagery: Option<PathBuf>,
    /// Imagery bands (1-based) to use as red,green,blue, e.g. `3,2,1`; one band gives grey.
    #[arg(long, value_delimiter = ',', requires = "imagery")]
    pub bands: Option<Vec<usize>>,
    /// The imagery's near-infrared band (1-based, e.g. 4 for Landsat 7): its NDVI against the red
    /// band (the first of `--bands`) is stored in the imagery's alpha, and seeds and texcells thin
    /// out where it says bare ground (`seeds.vegetation_*`). Needs three bands, rgba8 or bc7.
    #[arg(long, requires = "imagery")]
    pub nir_band: Option<usize>,
    /// A land-cover classification raster.
    #[arg(long, requires = "classes")]
    pub landcover: Option<PathBuf>,
    /// The land cover's class table: a built-in one (`nc`, `nlcd`) or a TOML file.
    #[arg(long, requires = "landcover")]
    pub classes: Option<String>,
    /// Store heights rounded to this step, metres: 0 keeps them exactly as read, else a power of
    /// two (0.25, 0.5, 1, …). Default: 0.25 of an integer DEM's unit (its warp's finer fractions
    /// are not data, and cost the packs most of their bytes), 0 for a floating-point DEM.
    #[arg(long, requires = "dem")]
    pub height_step_m: Option<f64>,
    /// A short name for logs (default: the DEM file's stem).
    #[arg(long, requires = "dem")]
    pub name: Option<String>,
}

#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("what").required(true).args(["dem", "plan"])))]
pub struct BuildArgs {
    #[command(flatten)]
    pub inputs: InputArgs,
    /// The output dataset folder (replaced atomically if it already holds a dataset).
    #[arg(long, requires = "dem")]
    pub out: Option<PathBuf>,
    /// How the imagery is stored: rgba8 (lossless), or blocks the GPU samples as they are, bc7
    /// (4× smaller, keeps coverage) or bc1 (8× smaller, imagery without holes only).
    #[arg(long, default_value = "rgba8", value_parser = crate::parse_imagery_format, requires = "imagery")]
    pub imagery_format: ImageryFormat,
    /// Build one partition of this plan (`terramp-data plan`) instead: its part packs, into the
    /// plan's parts folder.
    #[arg(long, requires = "partition", conflicts_with_all = ["dem", "imagery", "landcover", "out", "name", "height_step_m"])]
    pub plan: Option<PathBuf>,
    /// The partition to build, 0 to the plan's count − 1 (a scheduler's array index, e.g.
    /// `$JOB_COMPLETION_INDEX` or `$SLURM_ARRAY_TASK_ID`).
    #[arg(long, requires = "plan")]
    pub partition: Option<u32>,
}

pub fn run(args: &BuildArgs) -> Result<()> {
    let (Some(dem), Some(out)) = (&args.inputs.dem, &args.out) else {
        anyhow::bail!("build needs --dem and --out (or --plan and --partition)");
    };
    configure_gdal();
    let inputs = Inputs::open(&args.inputs, dem, args.imagery_format, None)?;
    let staging = Staging::begin(out).with_context(|| format!("preparing {}", out.display()))?;
    let progress = MultiProgress::new();
    let (manifest, scans) = write_layers(&inputs, inputs.name.clone(), &staging, &progress)?;
    let dir = staging.commit(&manifest).with_context(|| format!("publishing {}", out.display()))?;
    progress.clear().ok();
    print_summary(&dir, &manifest, &inputs, &scans);
    Ok(())
}

/// Every input, opened and checked before anything is written.
struct Inputs {
    name: String,
    frame: Frame,
    dem: GridRaster,
    height_step: HeightStep,
    footprint: Footprint,
    imagery: Option<Imagery>,
    imagery_format: ImageryFormat,
    landcover: Option<Landcover>,
}

impl Inputs {
    /// Opens `args`' inputs (`dem_path` is its DEM); the imagery's look measured, or `look`.
    fn open(
        args: &InputArgs,
        dem_path: &Path,
        imagery_format: ImageryFormat,
        look: Option<&ImageryLook>,
    ) -> Result<Self> {
        let dem_source = SourceRaster::open(dem_path, "DEM")?;
        let height_step = match args.height_step_m {
            Some(step_m) => HeightStep::new(step_m)?,
            None => HeightStep::default_for(&dem_source)?,
        };
        let frame = Frame::from_dem(&dem_source)?;
        let imagery = args.imagery.as_deref().map(|path| {
            let bands = (args.bands.as_deref(), args.nir_band);
            Imagery::open(path, bands, &frame, look)
        });
        if args.nir_band.is_some() {
            anyhow::ensure!(
                !imagery_format.holes_are_transparent(),
                "--nir-band stores the vegetation index in the imagery's alpha, which {} cannot hold \
                 (one bit): build with --imagery-format rgba8 or bc7",
                imagery_format.name()
            );
        }
        let landcover = match (&args.landcover, &args.classes) {
            (Some(path), Some(classes)) => Some(Landcover::open(path, classes, &frame)?),
            _ => None,
        };
        let dem = GridRaster::new(dem_source, &frame.dem_grid, &frame.srs, &[1], Resampling::Bilinear, true)?;
        let footprint = footprint(&dem, dem_path, &frame)?;
        Ok(Self {
            name: args.name.clone().unwrap_or_else(|| file_stem(dem_path)),
            imagery: imagery.transpose()?,
            imagery_format,
            landcover,
            dem,
            height_step,
            footprint,
            frame,
        })
    }
}

/// What the first passes over the inputs found, for the summary.
struct Scans {
    height: HeightScan,
    landcover: Option<LandcoverScan>,
}

/// Writes every layer's pack into the staging folder; returns the dataset's manifest.
fn write_layers(
    inputs: &Inputs,
    name: String,
    staging: &Staging,
    progress: &MultiProgress,
) -> Result<(Manifest, Scans)> {
    // A warp is read by every height pass: the scan keeps it for the others.
    let spill = match inputs.dem.access {
        Access::Warped => Some(SpilledGrid::create(&staging.path(".dem-warped.f32"), inputs.dem.grid.size)?),
        Access::Direct => None,
    };
    let mut scan =
        heights::scan(&inputs.dem, &inputs.footprint, spill, &bar(progress, "scan DEM", "blocks"))?;
    let height_bars = [&bar(progress, "heights", "tiles"), &bar(progress, "valid mask", "tiles")];
    let spacing_m = inputs.frame.dem_grid.pixel_m;
    let height = heights::write(&inputs.dem, &scan, inputs.height_step, spacing_m, staging, height_bars)?;
    scan.spill = None;
    let imagery = match &inputs.imagery {
        Some(source) => {
            let mut layer = source.write(staging, &bar(progress, "imagery", "tiles"))?;
            let blocks = bar(progress, inputs.imagery_format.short_name(), "tiles");
            encode_staged_imagery(staging, &mut layer, inputs.imagery_format, &blocks)
                .context("encoding the imagery's blocks")?;
            Some(layer)
        }
        None => None,
    };
    let landcover = match &inputs.landcover {
        Some(l) => {
            let scan = l.scan(&bar(progress, "scan codes", "windows"))?;
            Some((l.write(&scan, staging, &bar(progress, "land cover", "tiles"))?, scan))
        }
        None => None,
    };
    let (landcover, landcover_scan) = landcover.unzip();
    let earth = earth::place(&inputs.frame, &height)?;
    let manifest = Manifest {
        format_version: FORMAT_VERSION,
        name,
        crs: inputs.frame.crs.clone(),
        origin_m: inputs.frame.origin_m(),
        height,
        vegetation: inputs.imagery.as_ref().and_then(Imagery::vegetation),
        imagery,
        landcover,
        earth,
    };
    Ok((manifest, Scans { height: scan, landcover: landcover_scan }))
}

/// Small block cache, and GDAL's own messages kept off stderr: its errors reach the user through
/// the results of the calls that failed, with the file named.
fn configure_gdal() {
    gdal_ffi::set_block_cache_bytes(GDAL_BLOCK_CACHE_BYTES);
    gdal::config::set_error_handler(|_, _, _| {});
}

/// How the scan tells the source's voids from the grid beyond its edge. For a warped DEM with
/// nodata, that is the DEM warped again as if it had none: where even that is `NaN`, the grid lies
/// beyond the source's edge.
fn footprint(dem: &GridRaster, path: &Path, frame: &Frame) -> Result<Footprint> {
    if dem.access == Access::Direct {
        return Ok(Footprint::Whole);
    }
    let source = SourceRaster::open(path, "DEM")?;
    if source.nodata(1)?.is_none() {
        return Ok(Footprint::NoNodata);
    }
    let coverage = GridRaster::new(source, &frame.dem_grid, &frame.srs, &[1], Resampling::Bilinear, false)?;
    Ok(Footprint::Coverage(coverage))
}

fn bar(progress: &MultiProgress, name: &str, unit: &str) -> ProgressBar {
    let template = format!("{{prefix:>11}} {{bar:40}} {{pos}}/{{len}} {unit} {{elapsed}}");
    let style = ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar());
    progress.add(ProgressBar::new(0).with_style(style).with_prefix(name.to_owned()))
}

fn file_stem(path: &Path) -> String {
    path.file_stem().map_or_else(|| "dataset".to_owned(), |s| s.to_string_lossy().into_owned())
}

fn describe_access(access: Access) -> &'static str {
    match access {
        Access::Direct => "copied",
        Access::Warped => "reprojected",
    }
}

fn describe_grid(grid: &Grid, access: Access) -> String {
    format!("{} × {} texels of {} m, {}", grid.size[0], grid.size[1], grid.pixel_m, describe_access(access))
}

fn print_summary(dir: &Path, manifest: &Manifest, inputs: &Inputs, scans: &Scans) {
    let scan = &scans.height;
    let height = &manifest.height;
    println!("wrote {} ({})", dir.display(), manifest.name);
    println!("  frame: {}", manifest.crs.note);
    println!(
        "  heights: {} × {} samples {} m apart, {} .. {} m, {}, {}",
        height.pyramid.size[0],
        height.pyramid.size[1],
        height.spacing_m,
        height.min_m,
        height.max_m,
        describe_access(inputs.dem.access),
        height.step_m.map_or_else(|| "stored exactly".to_owned(), |s| format!("rounded to {s} m")),
    );
    println!(
        "  filled {} samples: {} voids in the source, {} beyond its edge",
        height.filled_samples, scan.source_voids, scan.beyond_edge
    );
    if let Some(imagery) = &inputs.imagery {
        let bands: Vec<String> = imagery.bands.iter().map(usize::to_string).collect();
        println!(
            "  imagery: {}, bands {}, stored as {}",
            describe_grid(imagery.grid(), imagery.access()),
            bands.join(","),
            inputs.imagery_format.name()
        );
    }
    if let (Some(landcover), Some(lcc)) = (&inputs.landcover, &scans.landcover) {
        let table = landcover.table();
        println!(
            "  land cover: {}, scheme {}; {} codes in {}-bit LCC words; {} texels carry codes outside the table (no class)",
            describe_grid(landcover.grid(), landcover.access()),
            table.scheme,
            lcc.coding.palette.len(),
            lcc.coding.word_bits,
            lcc.unknown_texels(table)
        );
    }
}
