//! How it works: a GeoTIFF build cut into partitions (`terramp::dataset::partition`), whose merge
//! equals `build`'s dataset from the same inputs byte for byte.
//!
//! Every tile of `build` depends on its own window of the inputs, and on a few things measured
//! over the whole of them: the DEM's range, its voids and the coarse surface the void fill falls
//! back on (the scan), the imagery's stretch and its no-data colour (its look), and the land
//! cover's palette. `plan` measures those once (`GeotiffSource::plan`), and the plan hands them to
//! every job; the coarse surface, up to 512 × 512 heights, goes into a file beside the plan whose
//! CRC the plan records. A job (`GeotiffParts::open`) opens the inputs as `build` does, with the
//! planned look instead of measuring one, and writes its subtrees of each layer from windows of
//! its own: the fill gives a void the same value in any window, and GDAL's warped VRT warps block
//! by block on a grid of its own, so a texel is the same whichever window reads it. The merge
//! assembles the layers and writes `build`'s manifest.
//!
//! The inputs are recorded by absolute path, byte length and CRC-32 of their contents, which the
//! plan's hash covers: new inputs make a new plan, whose jobs rebuild every partition. A job checks
//! each input's length (not its CRC, which would read whole files on every job). A GDAL virtual
//! path (`/vsis3/…`, `/vsicurl/…`) is recorded by its path alone: only GDAL reads it.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};
use terramp::dataset::block_encode::encode_staged_imagery;
use terramp::dataset::lcc::{LCC_SOURCE_LEVEL, LccCoding, lcc_pyramid};
use terramp::dataset::partition::{Split, merge_layer, merge_lcc, write_layer_part, write_lcc_part};
use terramp::dataset::{FORMAT_VERSION, ImageryFormat, LayerSpec, Manifest, Staging};

use super::fill::{CoarseGrid, VoidFill};
use super::heights::{self, HEIGHT_PACK, HeightSource, VALID_MASK_PACK};
use super::imagery::{IMAGERY_PACK, ImageryLook};
use super::landcover::LANDCOVER_PACK;
use super::{InputArgs, Inputs, configure_gdal};

/// One input file as the plan saw it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputFile {
    pub path: PathBuf,
    pub bytes: u64,
    /// CRC-32 of the whole file, hexadecimal.
    pub crc32: String,
}

impl InputFile {
    /// Reads `path` once for its length and CRC (a GDAL virtual path: its path alone).
    fn measure(path: &Path) -> Result<Self> {
        use std::io::Read;
        if is_virtual(path) {
            return Ok(Self { path: path.to_owned(), bytes: 0, crc32: VIRTUAL_CRC.to_owned() });
        }
        let path = std::path::absolute(path).with_context(|| format!("resolving {}", path.display()))?;
        let mut file = fs::File::open(&path).with_context(|| format!("reading {}", path.display()))?;
        let (mut hasher, mut bytes, mut buffer) = (crc32fast::Hasher::new(), 0u64, vec![0u8; 1 << 20]);
        loop {
            let n = file.read(&mut buffer).with_context(|| format!("reading {}", path.display()))?;
            if n == 0 {
                break;
            }
            hasher.update(&buffer[..n]);
            bytes += n as u64;
        }
        Ok(Self { path, bytes, crc32: format!("{:08x}", hasher.finalize()) })
    }

    /// Fails unless the file is still there with the planned length.
    fn check(&self) -> Result<()> {
        if is_virtual(&self.path) {
            return Ok(());
        }
        let bytes = fs::metadata(&self.path)
            .with_context(|| format!("{}: an input of the plan is missing", self.path.display()))?
            .len();
        ensure!(
            bytes == self.bytes,
            "{}: {bytes} bytes, the plan was made from {} (the input changed since: plan again)",
            self.path.display(),
            self.bytes
        );
        Ok(())
    }
}

/// What a GDAL virtual path's CRC is recorded as.
const VIRTUAL_CRC: &str = "not read: a GDAL virtual path";

/// Whether `path` is one of GDAL's virtual file systems (`/vsis3/`, `/vsicurl/`, `/vsizip/`, …).
fn is_virtual(path: &Path) -> bool {
    path.to_str().is_some_and(|p| p.starts_with("/vsi"))
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedImagery {
    pub file: InputFile,
    pub bands: Vec<usize>,
    /// The near-infrared band whose NDVI the alpha carries (`--nir-band`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nir_band: Option<usize>,
    pub look: ImageryLook,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedLandcover {
    pub file: InputFile,
    /// The class table, as `--classes` named it (a built-in name, or a TOML file's path).
    pub classes: String,
}

/// What the DEM's scan found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannedHeights {
    /// Range of the valid heights as read, metres.
    pub range_m: [f32; 2],
    pub source_voids: u64,
    pub beyond_edge: u64,
    /// The void fill's coarse surface, a file beside the plan (when the DEM has voids).
    pub coarse: Option<InputFile>,
}

/// A planned GeoTIFF build: its inputs and what was measured over the whole of them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeotiffSource {
    pub name: String,
    pub dem: InputFile,
    /// Metres (0: heights exactly as read).
    pub height_step_m: f64,
    pub heights: PlannedHeights,
    pub imagery: Option<PlannedImagery>,
    pub landcover: Option<PlannedLandcover>,
}

impl GeotiffSource {
    /// Opens and scans `args`' inputs; the void fill's coarse surface, if any, goes to `coarse`.
    /// Returns the source and the land cover's coding.
    pub fn plan(args: &InputArgs, coarse: &Path) -> Result<(Self, Option<LccCoding>)> {
        let Some(dem) = &args.dem else { bail!("plan needs --dem (or --synth-size)") };
        configure_gdal();
        let inputs = Inputs::open(args, dem, ImageryFormat::Rgba8, None)?;
        let scan = heights::scan(&inputs.dem, &inputs.footprint, None, &bar("scan DEM"))?;
        let coarse = match &scan.fill {
            Some(fill) => {
                crate::plan::write_atomically(coarse, &fill.coarse().to_bytes())?;
                Some(InputFile::measure(coarse)?)
            }
            None => None,
        };
        let coding = match &inputs.landcover {
            Some(landcover) => Some(landcover.scan(&bar("scan codes"))?.coding),
            None => None,
        };
        let imagery = match (&inputs.imagery, &args.imagery) {
            (Some(imagery), Some(path)) => Some(PlannedImagery {
                file: InputFile::measure(path)?,
                bands: imagery.bands.clone(),
                nir_band: args.nir_band,
                look: imagery.look(),
            }),
            _ => None,
        };
        let landcover = match (&args.landcover, &args.classes) {
            (Some(path), Some(classes)) => {
                Some(PlannedLandcover { file: InputFile::measure(path)?, classes: classes.clone() })
            }
            _ => None,
        };
        let source = Self {
            name: inputs.name.clone(),
            dem: InputFile::measure(dem)?,
            height_step_m: inputs.height_step.metres(),
            heights: PlannedHeights {
                range_m: scan.range_m,
                source_voids: scan.source_voids,
                beyond_edge: scan.beyond_edge,
                coarse,
            },
            imagery,
            landcover,
        };
        Ok((source, coding))
    }

    /// The arguments `build` would be given for the same dataset.
    fn args(&self) -> InputArgs {
        InputArgs {
            dem: Some(self.dem.path.clone()),
            imagery: self.imagery.as_ref().map(|i| i.file.path.clone()),
            bands: self.imagery.as_ref().map(|i| i.bands.clone()),
            nir_band: self.imagery.as_ref().and_then(|i| i.nir_band),
            landcover: self.landcover.as_ref().map(|l| l.file.path.clone()),
            classes: self.landcover.as_ref().map(|l| l.classes.clone()),
            height_step_m: Some(self.height_step_m),
            name: Some(self.name.clone()),
        }
    }
}

/// A planned GeoTIFF build's inputs, opened for its jobs and its merge.
pub struct GeotiffParts {
    source: GeotiffSource,
    inputs: Inputs,
    fill: Option<VoidFill>,
    coding: Option<LccCoding>,
    /// Per layer written: its pack's name, its split, and its source level.
    pub splits: Vec<(&'static str, Split, u32)>,
}

impl GeotiffParts {
    /// Opens `source`'s inputs for `partitions` jobs; `plan_dir` holds the coarse surface's file.
    pub fn open(
        source: &GeotiffSource,
        coding: Option<LccCoding>,
        partitions: u32,
        plan_dir: &Path,
    ) -> Result<Self> {
        configure_gdal();
        let files = [Some(&source.dem), source.imagery.as_ref().map(|i| &i.file)];
        files
            .into_iter()
            .flatten()
            .chain(source.landcover.as_ref().map(|l| &l.file))
            .try_for_each(InputFile::check)?;
        let look = source.imagery.as_ref().map(|i| &i.look);
        let inputs = Inputs::open(&source.args(), &source.dem.path, ImageryFormat::Rgba8, look)?;
        let size = inputs.dem.grid.size;
        let fill = match &source.heights.coarse {
            Some(file) => {
                let path = plan_dir.join(&file.path);
                let bytes = fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
                let crc = format!("{:08x}", crc32fast::hash(&bytes));
                let coarse = CoarseGrid::from_bytes(&bytes).filter(|_| crc == file.crc32);
                let Some(coarse) = coarse else {
                    bail!("{}: not the coarse surface the plan was made with (plan again)", path.display())
                };
                Some(VoidFill::new(size, coarse, source.heights.range_m))
            }
            None => None,
        };
        let mut splits =
            vec![(HEIGHT_PACK, Split::new(LayerSpec::heights(size).pyramid, partitions, 4, 0), 0)];
        if fill.is_some() {
            splits.push((
                VALID_MASK_PACK,
                Split::new(LayerSpec::valid_mask(size).pyramid, partitions, 1, 0),
                0,
            ));
        }
        if let Some(imagery) = &inputs.imagery {
            splits.push((IMAGERY_PACK, Split::new(imagery.spec().pyramid, partitions, 4, 0), 0));
        }
        match (&inputs.landcover, &coding) {
            (Some(landcover), Some(coding)) => {
                let pyramid = lcc_pyramid(landcover.grid().size);
                let split = Split::new(pyramid, partitions, coding.word_bytes() as u64, LCC_SOURCE_LEVEL);
                splits.push((LANDCOVER_PACK, split, LCC_SOURCE_LEVEL));
            }
            (None, None) => {}
            _ => bail!("the plan's land cover and its coding disagree (was the plan edited?)"),
        }
        Ok(Self { source: source.clone(), inputs, fill, coding, splits })
    }

    fn heights(&self) -> HeightSource<'_> {
        let step = self.inputs.height_step;
        HeightSource { dem: &self.inputs.dem, spill: None, fill: self.fill.as_ref(), step }
    }

    /// Writes partition `part`'s part packs into the folder `dir` (which must exist).
    pub fn write_part(&self, dir: &Path, part: u32, progress: bool) -> Result<()> {
        let heights = self.heights();
        let size = self.inputs.dem.grid.size;
        for (pack, split, _) in &self.splits {
            let (path, bar) = (dir.join(pack), bar_if(progress, pack));
            let written = match *pack {
                HEIGHT_PACK => write_layer_part(
                    &path,
                    &LayerSpec::heights(size),
                    split,
                    part,
                    |w| Ok(heights.heights(w)?.0),
                    &bar,
                ),
                VALID_MASK_PACK => write_layer_part(
                    &path,
                    &LayerSpec::valid_mask(size),
                    split,
                    part,
                    |w| heights.valid(w),
                    &bar,
                ),
                IMAGERY_PACK => {
                    let imagery = self.imagery()?;
                    write_layer_part(&path, &imagery.spec(), split, part, |w| imagery.texels(w), &bar)
                }
                _ => {
                    let (landcover, coding) = self.landcover()?;
                    let codes = |w| landcover.codes(w);
                    write_lcc_part(&path, landcover.grid().size, coding, split, part, codes, &bar)
                }
            };
            written.with_context(|| format!("writing partition {part} of {pack}"))?;
            bar.finish();
        }
        Ok(())
    }

    /// Merges the part folders `parts` (partition 0 first) into the dataset at `out`, atomically,
    /// its imagery stored as `imagery_format`.
    pub fn merge(
        &self,
        parts: &[PathBuf],
        out: &Path,
        imagery_format: ImageryFormat,
        progress: bool,
    ) -> Result<PathBuf> {
        let staging = Staging::begin(out).with_context(|| format!("preparing {}", out.display()))?;
        let size = self.inputs.dem.grid.size;
        let (mut imagery, mut landcover) = (None, None);
        for (pack, split, _) in &self.splits {
            let (path, bar) = (staging.path(pack), bar_if(progress, pack));
            let packs: Vec<PathBuf> = parts.iter().map(|dir| dir.join(pack)).collect();
            let merged = match *pack {
                HEIGHT_PACK => merge_layer::<f32>(&path, &LayerSpec::heights(size), split, &packs, &bar),
                VALID_MASK_PACK => {
                    merge_layer::<u8>(&path, &LayerSpec::valid_mask(size), split, &packs, &bar)
                }
                IMAGERY_PACK => {
                    let source = self.imagery()?;
                    imagery = Some(source.layer());
                    merge_layer::<[u8; 4]>(&path, &source.spec(), split, &packs, &bar)
                }
                _ => {
                    let (source, coding) = self.landcover()?;
                    let size = source.grid().size;
                    landcover = Some(source.layer(lcc_pyramid(size), coding.clone()));
                    merge_lcc(&path, size, coding, split, &packs, &bar)
                }
            };
            merged.with_context(|| format!("merging {pack}"))?;
            bar.finish();
        }
        if let Some(layer) = imagery.as_mut() {
            let blocks = bar_if(progress, imagery_format.short_name());
            encode_staged_imagery(&staging, layer, imagery_format, &blocks)
                .context("encoding the imagery's blocks")?;
        }
        let planned = &self.source.heights;
        let height = heights::height_layer(
            LayerSpec::heights(size).pyramid,
            self.inputs.frame.dem_grid.pixel_m,
            planned.range_m,
            self.heights().step,
            planned.source_voids + planned.beyond_edge,
            self.fill.is_some(),
        );
        let earth = super::earth::place(&self.inputs.frame, &height)?;
        let manifest = Manifest {
            format_version: FORMAT_VERSION,
            name: self.source.name.clone(),
            crs: self.inputs.frame.crs.clone(),
            origin_m: self.inputs.frame.origin_m(),
            height,
            vegetation: self.inputs.imagery.as_ref().and_then(super::Imagery::vegetation),
            imagery,
            landcover,
            earth,
        };
        staging.commit(&manifest).with_context(|| format!("publishing {}", out.display()))
    }

    fn imagery(&self) -> Result<&super::Imagery> {
        self.inputs.imagery.as_ref().context("the plan has no imagery")
    }

    fn landcover(&self) -> Result<(&super::Landcover, &LccCoding)> {
        self.inputs.landcover.as_ref().zip(self.coding.as_ref()).context("the plan has no land cover")
    }
}

fn bar(name: &str) -> ProgressBar {
    bar_if(std::io::IsTerminal::is_terminal(&std::io::stderr()), name)
}

/// A progress bar of tiles on stderr, drawn only when `progress`.
fn bar_if(progress: bool, name: &str) -> ProgressBar {
    if !progress {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template("{prefix:>18} {bar:40} {pos}/{len} {elapsed}")
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    ProgressBar::new(0).with_style(style).with_prefix(name.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gdal_virtual_path_is_recorded_by_its_path_alone() {
        let path = Path::new("/vsis3/terrain/dem.tif");
        let file = InputFile::measure(path).unwrap();
        assert_eq!((file.path.as_path(), file.bytes, file.crc32.as_str()), (path, 0, VIRTUAL_CRC));
        assert!(file.check().is_ok(), "a job cannot stat a virtual path, and does not");
        let missing = InputFile { path: "/nonexistent/dem.tif".into(), bytes: 1, crc32: "0".into() };
        assert!(missing.check().unwrap_err().to_string().contains("/nonexistent/dem.tif"));
    }
}
