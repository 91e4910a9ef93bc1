//! How it works: imagery becomes 8-bit sRGB with alpha, on the DEM's extent at the source's own
//! pixel size. One band gives grey, three give red, green, blue (`--bands`, 1-based).
//!
//! 8-bit sources are display-ready and kept as they are. Anything wider (reflectances, 16-bit
//! counts) is stretched per band from its 2nd to its 98th percentile, measured on a subsampled
//! read of the whole source, so a few outliers cannot wash the picture out. A palette band is
//! looked up in its colour table (and resampled nearest, since blending indices is meaningless),
//! unless the palette is a plain grey ramp, which is just grey values.
//!
//! Texels without data get alpha 0 and the mean colour of the valid ones, so that mips and
//! filtering near the imagery's edge fade to a plausible colour instead of pulling in black.

use std::path::Path;

use anyhow::{Context, Result, ensure};
use gdal::raster::{ColorInterpretation, GdalDataType};
use indicatif::ProgressBar;
use serde::{Deserialize, Serialize};
use terramp::dataset::{
    CellLayer, IMAGERY_MIPS, LayerSpec, Staging, Vegetation, Window, vegetation, write_layer,
};

use super::frame::{Frame, Grid};
use super::raster::{Access, GridRaster, Resampling, SourceRaster};

pub const IMAGERY_PACK: &str = "imagery.pack";
/// The stretch is measured on at most this many texels per side of the source.
const SAMPLE_SIDE: usize = 1024;
const STRETCH_PERCENTILES: [f64; 2] = [0.02, 0.98];

/// How one band's values become 0..=255.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "tone", rename_all = "snake_case", deny_unknown_fields)]
pub enum Tone {
    Identity,
    Stretch { low: f64, high: f64 },
}

impl Tone {
    fn apply(self, value: f64) -> u8 {
        let scaled = match self {
            Tone::Identity => value,
            Tone::Stretch { low, high } => (value - low) / (high - low) * 255.0,
        };
        scaled.round().clamp(0.0, 255.0) as u8
    }
}

/// How the bands read become a colour.
enum Colour {
    /// One tone per band: one band is grey, three are red, green, blue.
    Bands(Vec<Tone>),
    /// Palette indices and their colours; entries with alpha 0 mean no data.
    Palette(Vec<Option<[u8; 3]>>),
}

impl Colour {
    /// The colour of one texel from its band values, `None` without data.
    fn rgb(&self, values: &[f64]) -> Option<[u8; 3]> {
        if values.iter().any(|v| v.is_nan()) {
            return None;
        }
        match self {
            Colour::Bands(tones) => {
                let mut channels = tones.iter().zip(values).map(|(tone, &v)| tone.apply(v));
                let first = channels.next()?;
                Some([first, channels.next().unwrap_or(first), channels.next().unwrap_or(first)])
            }
            Colour::Palette(entries) => *entries.get(values[0].round().clamp(0.0, 255.0) as usize)?,
        }
    }
}

/// What the imagery's colours depend on beyond each texel, measured over the whole source: a
/// partitioned build measures it once, in the plan, for every job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageryLook {
    /// Per band read; empty for a palette, whose colours are the file's own.
    pub tones: Vec<Tone>,
    /// The colour of texels without data.
    pub fill_rgb: [u8; 3],
}

/// An imagery input, ready to be tiled.
pub struct Imagery {
    raster: GridRaster,
    colour: Colour,
    /// The colour of texels without data: the mean of the valid ones.
    fill_rgb: [u8; 3],
    pub bands: Vec<usize>,
    /// The near-infrared band read after `bands`, whose NDVI against the red band (the first of
    /// `bands`) the alpha carries (`terramp::dataset::vegetation`).
    nir_band: Option<usize>,
}

impl Imagery {
    /// Opens the imagery at `path` on `frame`'s extent; its look measured from the source, or
    /// `look` (a plan's) when given.
    pub fn open(
        path: &Path,
        (bands, nir_band): (Option<&[usize]>, Option<usize>),
        frame: &Frame,
        look: Option<&ImageryLook>,
    ) -> Result<Self> {
        let source = SourceRaster::open(path, "imagery")?;
        let bands = choose_bands(&source, bands).with_context(|| format!("imagery {}", path.display()))?;
        if let Some(nir) = nir_band {
            let count = source.dataset.raster_count();
            ensure!(
                bands.len() == 3 && (1..=count).contains(&nir),
                "imagery {}: --nir-band {nir} needs three colour bands (the first is red) and a band \
                 that exists (the raster has {count})",
                path.display()
            );
        }
        let grid = frame.cell_grid(&source)?;
        let (colour, fill_rgb) = match look {
            Some(look) => (colour_planned(&source, &bands, look)?, look.fill_rgb),
            None => {
                let colour = colour_of(&source, &bands)?;
                let fill_rgb = mean_colour(&source, &bands, &colour)?;
                (colour, fill_rgb)
            }
        };
        let resampling = match colour {
            Colour::Palette(_) => Resampling::Nearest,
            Colour::Bands(_) => Resampling::Bilinear,
        };
        let read: Vec<usize> = bands.iter().copied().chain(nir_band).collect();
        let raster = GridRaster::new(source, &grid, &frame.srs, &read, resampling, true)?;
        Ok(Self { raster, colour, fill_rgb, bands, nir_band })
    }

    /// The look this imagery's colours were made with.
    pub fn look(&self) -> ImageryLook {
        let tones = match &self.colour {
            Colour::Bands(tones) => tones.clone(),
            Colour::Palette(_) => Vec::new(),
        };
        ImageryLook { tones, fill_rgb: self.fill_rgb }
    }

    pub fn grid(&self) -> &Grid {
        &self.raster.grid
    }

    pub fn access(&self) -> Access {
        self.raster.access
    }

    pub fn spec(&self) -> LayerSpec {
        LayerSpec::imagery(self.grid().size)
    }

    /// The texels of `window`, sRGB with alpha 0 where the source has no data.
    pub fn texels(&self, window: Window) -> Result<Vec<[u8; 4]>, String> {
        let bands = self.raster.read(window)?;
        let mut values = vec![0.0; bands.len()];
        Ok((0..(window.width * window.height) as usize)
            .map(|k| {
                values.iter_mut().zip(&bands).for_each(|(v, band)| *v = band[k]);
                match self.colour.rgb(&values) {
                    Some([r, g, b]) => [r, g, b, self.alpha(&values)],
                    None => [self.fill_rgb[0], self.fill_rgb[1], self.fill_rgb[2], 0],
                }
            })
            .collect())
    }

    /// A texel's alpha, where it has data: full coverage, or the vegetation index coded
    /// (`vegetation::encode`; an index the bands do not define is 0, neither bare nor green).
    fn alpha(&self, values: &[f64]) -> u8 {
        match (self.nir_band, values.first(), values.get(self.bands.len())) {
            (Some(_), Some(&red), Some(&nir)) => {
                vegetation::encode(vegetation::ndvi(nir, red).unwrap_or(0.0))
            }
            _ => 255,
        }
    }

    /// What the manifest says of the vegetation index in the alpha, if any.
    pub fn vegetation(&self) -> Option<Vegetation> {
        let nir = self.nir_band?;
        let red = self.bands.first()?;
        Some(Vegetation {
            index: vegetation::NDVI.to_owned(),
            source: format!("bands {nir} (near infrared) and {red} (red) of {}", self.raster.path.display()),
        })
    }

    /// The manifest's imagery layer, as written in plain texels.
    pub fn layer(&self) -> CellLayer {
        CellLayer {
            pack: IMAGERY_PACK.to_owned(),
            texel_m: self.grid().pixel_m,
            pyramid: self.spec().pyramid,
            mips: IMAGERY_MIPS,
            format: "rgba8 srgb".to_owned(),
            source: self.raster.path.display().to_string(),
        }
    }

    pub fn write(&self, staging: &Staging, bar: &ProgressBar) -> Result<CellLayer> {
        write_layer(&staging.path(IMAGERY_PACK), &self.spec(), |w| self.texels(w), bar)
            .context("writing the imagery pack")?;
        Ok(self.layer())
    }
}

/// The bands asked for, or by default the first three (RGB) or the first one (grey).
fn choose_bands(source: &SourceRaster, asked: Option<&[usize]>) -> Result<Vec<usize>> {
    let count = source.dataset.raster_count();
    let bands = match asked {
        Some(bands) => bands.to_vec(),
        None if count >= 3 => vec![1, 2, 3],
        None => vec![1],
    };
    ensure!(
        matches!(bands.len(), 1 | 3),
        "--bands needs one band (grey) or three (red, green, blue), got {bands:?}"
    );
    for &band in &bands {
        ensure!((1..=count).contains(&band), "band {band} does not exist: the raster has {count} band(s)");
    }
    Ok(bands)
}

fn colour_of(source: &SourceRaster, bands: &[usize]) -> Result<Colour> {
    if let [band] = bands
        && let Some(palette) = palette(source, *band)?
    {
        return Ok(Colour::Palette(palette));
    }
    let tones = bands
        .iter()
        .map(|&band| {
            if source.band(band)?.band_type() == GdalDataType::UInt8 {
                return Ok(Tone::Identity);
            }
            let valid = subsample(source, band)?.into_iter().filter(|v| !v.is_nan()).collect();
            let [low, high] = percentiles(valid, STRETCH_PERCENTILES).with_context(|| {
                format!("imagery {}: band {band} holds no valid value", source.path.display())
            })?;
            Ok(Tone::Stretch { low, high: if high > low { high } else { low + 1.0 } })
        })
        .collect::<Result<_>>()?;
    Ok(Colour::Bands(tones))
}

/// The colour of a plan's `look`: its tones, or the band's palette when the look has none.
fn colour_planned(source: &SourceRaster, bands: &[usize], look: &ImageryLook) -> Result<Colour> {
    if look.tones.is_empty()
        && let [band] = bands
        && let Some(palette) = palette(source, *band)?
    {
        return Ok(Colour::Palette(palette));
    }
    ensure!(
        look.tones.len() == bands.len(),
        "imagery {}: the plan has {} tones for {} bands (was the file replaced since the plan?)",
        source.path.display(),
        look.tones.len(),
        bands.len()
    );
    Ok(Colour::Bands(look.tones.clone()))
}

/// The band's palette, unless it has none or it is a plain grey ramp (entry i = grey i).
fn palette(source: &SourceRaster, band: usize) -> Result<Option<Vec<Option<[u8; 3]>>>> {
    let band = source.band(band)?;
    if band.color_interpretation() != ColorInterpretation::PaletteIndex {
        return Ok(None);
    }
    let Some(table) = band.color_table() else { return Ok(None) };
    let channel = |v: i16| v.clamp(0, 255) as u8;
    let entries: Vec<Option<[u8; 3]>> = (0..table.entry_count().min(256))
        .map(|i| table.entry_as_rgb(i).filter(|e| e.a > 0).map(|e| [e.r, e.g, e.b].map(channel)))
        .collect();
    let grey_ramp = entries.iter().enumerate().all(|(i, e)| e.is_none_or(|rgb| rgb == [i as u8; 3]));
    Ok((!grey_ramp).then_some(entries))
}

/// A subsampled read of the whole band (nearest), `NaN` where it has no data.
fn subsample(source: &SourceRaster, band: usize) -> Result<Vec<f64>> {
    let [width, height] = source.size;
    let shrink = width.max(height).div_ceil(SAMPLE_SIDE);
    let shape = (width.div_ceil(shrink), height.div_ceil(shrink));
    let mut values = vec![0.0; shape.0 * shape.1];
    let nodata = source.nodata(band)?;
    source
        .band(band)?
        .read_into_slice((0, 0), (width, height), shape, &mut values, None)
        .with_context(|| format!("imagery {}: reading band {band}", source.path.display()))?;
    values.iter_mut().filter(|v| Some(**v) == nodata).for_each(|v| *v = f64::NAN);
    Ok(values)
}

/// The values at the given fractions of the sorted `values`, `None` if there are none.
fn percentiles(mut values: Vec<f64>, fractions: [f64; 2]) -> Option<[f64; 2]> {
    if values.is_empty() {
        return None;
    }
    values.sort_unstable_by(f64::total_cmp);
    let last = (values.len() - 1) as f64;
    Some(fractions.map(|f| values[(f * last).round() as usize]))
}

/// The mean colour of the source's valid texels, on the subsampled read.
fn mean_colour(source: &SourceRaster, bands: &[usize], colour: &Colour) -> Result<[u8; 3]> {
    let samples: Vec<Vec<f64>> = bands.iter().map(|&band| subsample(source, band)).collect::<Result<_>>()?;
    let (mut sum, mut count) = ([0.0f64; 3], 0u64);
    let mut values = vec![0.0; bands.len()];
    for k in 0..samples[0].len() {
        values.iter_mut().zip(&samples).for_each(|(v, band)| *v = band[k]);
        if let Some(rgb) = colour.rgb(&values) {
            sum.iter_mut().zip(rgb).for_each(|(s, c)| *s += f64::from(c));
            count += 1;
        }
    }
    ensure!(count > 0, "imagery {}: holds no valid texel", source.path.display());
    Ok(sum.map(|s| (s / count as f64).round() as u8))
}
