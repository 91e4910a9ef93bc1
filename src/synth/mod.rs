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
//! The manifest's height range is the height pack's top tile's, which spans every sample. Land cover is
//! classified at 2 texels per spacing (the LCC quadtree's level 1): a first pass counts the codes
//! for the palette, a second writes the 3 levels (`crate::dataset::lcc`).

mod colour;
mod layers;
mod noise;
mod palette;
mod parts;
mod terrain;

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use thiserror::Error;

use crate::classes::ClassTableError;
use crate::dataset::block_encode::encode_staged_imagery;
use crate::dataset::lcc::{LccError, write_lcc_layer};
use crate::dataset::{
    DatasetError, ImageryFormat, LayerError, Manifest, PackError, Staging, Window, write_layer,
};

pub use colour::Painter;
pub use layers::{HEIGHT_PACK, IMAGERY_PACK, LANDCOVER_PACK};
pub use noise::Field;
pub use parts::SynthParts;
pub use terrain::{Ground, Parcel, Terrain, code};

use layers::Layers;

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
    /// How the imagery is stored: plain RGBA8, or BC1/BC7 blocks made from it.
    pub imagery_format: ImageryFormat,
}

impl Default for SynthParams {
    fn default() -> Self {
        Self {
            size: 1024,
            seed: 1,
            spacing_m: 10.0,
            origin_m: [0.0, 0.0],
            water_level_m: 100.0,
            imagery_format: ImageryFormat::Rgba8,
        }
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
    /// A written pack could not be read back.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// The built-in class table of the land-cover scheme could not be loaded.
    #[error(transparent)]
    Classes(#[from] ClassTableError),
    /// The land-cover codes could not be coded or written as an LCC layer.
    #[error(transparent)]
    Lcc(#[from] LccError),
}

/// Writes the synthetic dataset described by `params` to `out` (atomically replacing a dataset
/// there) and returns its folder. `progress` draws a bar per layer on stderr.
pub fn synthesize(out: &Path, params: &SynthParams, progress: bool) -> Result<PathBuf, SynthError> {
    let layers = Layers::new(params)?;
    let staging = Staging::begin(out)?;
    let bar = progress_bar(progress, "height");
    write_layer(&staging.path(HEIGHT_PACK), &layers.height, |w| layers.heights(w), &bar)?;
    bar.finish();
    let bar = progress_bar(progress, "imagery");
    write_layer(&staging.path(IMAGERY_PACK), &layers.imagery, |w| layers.paint(w), &bar)?;
    bar.finish();
    let bar = progress_bar(progress, "classes");
    let coding = layers.coding(&bar)?;
    bar.finish();
    let bar = progress_bar(progress, "landcover");
    let classify = |w: Window| layers.classify(w);
    write_lcc_layer(&staging.path(LANDCOVER_PACK), layers.class_texels, &coding, classify, &bar)?;
    bar.finish();
    let range = layers.height_range(&staging.path(HEIGHT_PACK))?;
    commit(staging, layers.manifest(range, coding)?, params.imagery_format, progress)
}

/// Stores the staged imagery in `imagery_format` (made from the plain pack written first), and
/// puts the dataset of `manifest` in place.
fn commit(
    staging: Staging,
    mut manifest: Manifest,
    imagery_format: ImageryFormat,
    progress: bool,
) -> Result<PathBuf, SynthError> {
    if let Some(imagery) = manifest.imagery.as_mut().filter(|_| imagery_format.is_block_compressed()) {
        let bar = progress_bar(progress, imagery_format.short_name());
        encode_staged_imagery(&staging, imagery, imagery_format, &bar)?;
        bar.finish();
    }
    Ok(staging.commit(&manifest)?)
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
