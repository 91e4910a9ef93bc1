//! How it works: `synthesize` writes a complete dataset (heights, imagery, land cover) of any size
//! from one continuous synthetic world (`Terrain`), through the same staging and layer writer as
//! real data. Each layer's source evaluates the world at its own texel centres, tile by tile, in
//! parallel: nothing is ever held whole, so giga-pixel imagery costs time, not memory.
//!
//! The world is anchored at the dataset's south-west height sample: a position is grid metres, not
//! CRS metres, so `origin_m` (UTM-like offsets) moves the world without changing a single sample,
//! and a dataset of half the spacing holds the same heights at the samples the two share. Height
//! samples sit at (i, j) · spacing; cell layers tile the pixel-area extent from half a spacing
//! south-west, so imagery texel (i, j) is centred at ((i, j) + ½) · spacing / 4 − spacing / 2.
//! The manifest's height range is gathered from the samples as they are written. Land cover is
//! classified at 2 texels per spacing (the LCC quadtree's level 1): a first pass counts the codes
//! for the palette, a second writes the 3 levels (`crate::dataset::lcc`).

mod colour;
mod noise;
mod palette;
mod terrain;

use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use indicatif::{ProgressBar, ProgressStyle};
use thiserror::Error;

use crate::classes::{ClassTable, ClassTableError};
use crate::dataset::lcc::{LccCoding, LccError, scan_codes, write_lcc_layer};
use crate::dataset::{
    CellLayer, Crs, DatasetError, FORMAT_VERSION, HeightLayer, LandcoverLayer, LayerError, LayerSpec,
    Manifest, Staging, Texel, Window, write_layer,
};

pub use colour::Painter;
pub use noise::Field;
pub use terrain::{Ground, Parcel, Terrain, code};

/// Imagery texels per DEM spacing, per axis.
pub const IMAGERY_PER_SPACING: u32 = 4;
/// Land-cover source texels (LCC level 1; level 0 has twice as many) per DEM spacing, per axis.
pub const LANDCOVER_PER_SPACING: u32 = 2;
/// Largest `size`: imagery is 4× finer and its texel indices must fit in u32.
pub const MAX_SIZE: u32 = 1 << 20;
/// The synthetic dataset's CRS (WKT): a local metric frame with no geodetic meaning.
pub const CRS_DEFINITION: &str = "LOCAL_CS[\"terramp synthetic\",UNIT[\"metre\",1]]";
const CLASS_SCHEME: &str = "nc";
const LANDCOVER_NODATA: u8 = 255;

/// What a synthetic dataset is made from: its size, seed, sample spacing, CRS origin and lake level.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthParams {
    /// DEM samples per side.
    pub size: u32,
    /// The same seed gives the same dataset, bit for bit.
    pub seed: u64,
    /// Distance between height samples, metres.
    pub spacing_m: f64,
    /// CRS position of the south-west height sample, metres.
    pub origin_m: [f64; 2],
    /// Height of lakes' surface, metres; the relief is built around it.
    pub water_level_m: f64,
}

impl Default for SynthParams {
    fn default() -> Self {
        Self { size: 1024, seed: 1, spacing_m: 10.0, origin_m: [0.0, 0.0], water_level_m: 100.0 }
    }
}

impl SynthParams {
    /// The world these parameters describe (its seed and water level; size and spacing only say
    /// where it is sampled).
    pub fn terrain(&self) -> Terrain {
        Terrain::new(self.seed, self.water_level_m)
    }
}

/// Why a synthetic dataset could not be written.
#[derive(Debug, Error)]
pub enum SynthError {
    /// `size` is 0 or above `MAX_SIZE` samples per side.
    #[error("synthetic size {0}: use 1 to {MAX_SIZE} samples per side")]
    Size(u32),
    /// `spacing_m` is not a positive, finite number of metres.
    #[error("spacing {0} m: must be a positive, finite number of metres")]
    Spacing(f64),
    /// `origin_m` or `water_level_m` is NaN or infinite.
    #[error("origin {0:?} / water level {1} m: must be finite")]
    NotFinite([f64; 2], f64),
    /// The output folder could not be staged or the finished dataset committed.
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// Writing a layer's pack failed.
    #[error(transparent)]
    Layer(#[from] LayerError),
    /// The built-in class table of the land-cover scheme could not be loaded.
    #[error(transparent)]
    Classes(#[from] ClassTableError),
    /// The land-cover codes could not be coded or written as an LCC layer.
    #[error(transparent)]
    Lcc(#[from] LccError),
}

/// File name of the height layer's pack in the dataset folder.
pub const HEIGHT_PACK: &str = "height.pack";
/// File name of the imagery layer's pack in the dataset folder.
pub const IMAGERY_PACK: &str = "imagery.pack";
/// File name of the land-cover layer's pack in the dataset folder.
pub const LANDCOVER_PACK: &str = "landcover.pack";

/// Writes the synthetic dataset described by `params` to `out` (atomically replacing a dataset
/// there) and returns its folder. `progress` draws a bar per layer on stderr.
pub fn synthesize(out: &Path, params: &SynthParams, progress: bool) -> Result<PathBuf, SynthError> {
    let &SynthParams { size, seed, spacing_m, origin_m, water_level_m } = params;
    if !(1..=MAX_SIZE).contains(&size) {
        return Err(SynthError::Size(size));
    }
    if !(spacing_m.is_finite() && spacing_m > 0.0) {
        return Err(SynthError::Spacing(spacing_m));
    }
    if !(origin_m.iter().all(|v| v.is_finite()) && water_level_m.is_finite()) {
        return Err(SynthError::NotFinite(origin_m, water_level_m));
    }
    let table = ClassTable::load(CLASS_SCHEME)?;
    let terrain = params.terrain();
    let painter = Painter::new(seed, &terrain);
    let staging = Staging::begin(out)?;

    let height = LayerSpec::heights([size; 2]);
    let range_m = Mutex::new([f32::INFINITY, f32::NEG_INFINITY]);
    let heights = |w: Window| {
        let samples =
            grid(w, |i, j| terrain.height_m(f64::from(i) * spacing_m, f64::from(j) * spacing_m) as f32);
        let (lo, hi) =
            samples.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| (lo.min(h), hi.max(h)));
        let mut range = range_m.lock().unwrap_or_else(PoisonError::into_inner);
        *range = [range[0].min(lo), range[1].max(hi)];
        Ok(samples)
    };
    let bar = progress_bar(progress, "height");
    write_layer(&staging.path(HEIGHT_PACK), &height, heights, &bar)?;
    bar.finish();
    let [min_m, max_m] = range_m.into_inner().unwrap_or_else(PoisonError::into_inner);

    let imagery = LayerSpec::imagery([size * IMAGERY_PER_SPACING; 2]);
    let texel_m = spacing_m / f64::from(IMAGERY_PER_SPACING);
    let paint = |w: Window| Ok(painter.paint_window(&terrain, w, spacing_m, texel_m));
    let bar = progress_bar(progress, "imagery");
    write_layer(&staging.path(IMAGERY_PACK), &imagery, paint, &bar)?;
    bar.finish();

    let class_texels = [size * LANDCOVER_PER_SPACING; 2];
    let class_m = spacing_m / f64::from(LANDCOVER_PER_SPACING);
    let classify = |w: Window| Ok(cells(w, spacing_m, class_m, |x_m, y_m| terrain.ground(x_m, y_m).class));
    let bar = progress_bar(progress, "classes");
    let coding = LccCoding::for_codes(scan_codes(class_texels, &classify, &bar)?.present())?;
    bar.finish();
    let bar = progress_bar(progress, "landcover");
    let landcover = write_lcc_layer(&staging.path(LANDCOVER_PACK), class_texels, &coding, classify, &bar)?;
    bar.finish();

    let cell_layer = |pack: &str, texel_m: f64, spec: &LayerSpec, format: &str| CellLayer {
        pack: pack.into(),
        texel_m,
        pyramid: spec.pyramid,
        mips: spec.mips,
        format: format.into(),
        source: format!("synthetic (seed {seed})"),
    };
    let manifest = Manifest {
        format_version: FORMAT_VERSION,
        name: "synthetic".into(),
        crs: Crs {
            definition: CRS_DEFINITION.into(),
            note: format!(
                "terramp-data synth: size {size}, seed {seed}, spacing {spacing_m} m, water level {water_level_m} m"
            ),
        },
        origin_m,
        height: HeightLayer {
            pack: HEIGHT_PACK.into(),
            spacing_m,
            pyramid: height.pyramid,
            min_m,
            max_m,
            filled_samples: 0,
            valid_mask_pack: None,
        },
        imagery: Some(cell_layer(IMAGERY_PACK, texel_m, &imagery, "rgba8 srgb")),
        landcover: Some(LandcoverLayer {
            layer: CellLayer {
                pack: LANDCOVER_PACK.into(),
                texel_m: 0.5 * class_m,
                pyramid: landcover,
                mips: 1,
                format: coding.format_name(),
                source: format!("synthetic (seed {seed})"),
            },
            coding,
            classes: table.names(),
            scheme: table.scheme,
            nodata_code: LANDCOVER_NODATA,
        }),
    };
    Ok(staging.commit(&manifest)?)
}

/// The window's texels from `f(i, j)`, south row first.
fn grid<T: Texel>(w: Window, f: impl Fn(u32, u32) -> T) -> Vec<T> {
    let mut out = Vec::with_capacity(w.width as usize * w.height as usize);
    for j in w.y0..w.y0 + w.height {
        out.extend((w.x0..w.x0 + w.width).map(|i| f(i, j)));
    }
    out
}

/// The window's cell texels from `f(x_m, y_m)` at their centres in grid space, where cells of
/// `texel_m` tile the DEM's pixel area from half a `spacing_m` south-west of sample (0, 0).
fn cells<T: Texel>(w: Window, spacing_m: f64, texel_m: f64, f: impl Fn(f64, f64) -> T) -> Vec<T> {
    let centre = |i: u32| (f64::from(i) + 0.5) * texel_m - 0.5 * spacing_m;
    grid(w, |i, j| f(centre(i), centre(j)))
}

fn progress_bar(progress: bool, layer: &str) -> ProgressBar {
    if !progress {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} tiles, {elapsed}")
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
    ProgressBar::new(0).with_style(style).with_message(layer.to_owned())
}
