//! How it works: `manifest.toml` describes a dataset folder: its frame (CRS and where grid space
//! sits in it), and for each layer its pack file, texel size and tile pyramid. It is the last file a
//! build writes, so a folder with a readable manifest is a complete dataset.
//!
//! Frames: grid space is metres east (x) and north (y) of `origin_m`, the CRS position of the
//! south-west height sample. Heights are vertex samples `spacing_m` apart; cell layers (imagery,
//! land cover) tile the DEM's pixel-area extent, which starts half a spacing south-west of it.

use serde::{Deserialize, Serialize};

use super::pyramid::{Pyramid, Sampling};
use crate::dataset::lcc::LccCoding;
use crate::earth::EarthFrame;

/// Version 2: land cover is the LCC quadtree of palette indices (`crate::dataset::lcc`).
pub const FORMAT_VERSION: u32 = 2;
/// File name of the manifest in a dataset folder; a build writes it last, so it marks a complete one.
pub const MANIFEST_FILE: &str = "manifest.toml";

/// The contents of `manifest.toml`: where grid space sits in the CRS, and each layer's pack and shape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The dataset format this manifest follows; `Dataset::open` reads only `FORMAT_VERSION`.
    pub format_version: u32,
    /// A short name for logs (the DEM file's stem, or "synthetic").
    pub name: String,
    /// The metric CRS that `origin_m` is in.
    pub crs: Crs,
    /// CRS coordinates (metres) of grid sample (0, 0): the south-west height sample.
    pub origin_m: [f64; 2],
    /// The DEM, which every dataset has; it defines grid space.
    pub height: HeightLayer,
    /// The aerial imagery; absent in a dataset built without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imagery: Option<CellLayer>,
    /// The land cover; absent in a dataset built without it (the ground is then bare everywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub landcover: Option<LandcoverLayer>,
    /// The imagery's vegetation index, carried in its alpha (`dataset::vegetation`); absent where
    /// the alpha is the imagery's coverage alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vegetation: Option<Vegetation>,
    /// Where the CRS's points lie on the Earth (`earth`); absent for a CRS the builder could not
    /// place (and for datasets built before it did).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub earth: Option<EarthFrame>,
}

/// A vegetation index computed at build time at the imagery's resolution and stored in its alpha
/// channel (`dataset::vegetation`): seeds and texcells thin out where it says bare ground.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vegetation {
    /// Which index: "ndvi", (NIR − red) / (NIR + red).
    pub index: String,
    /// Where it came from, for the record (the bands and the file).
    pub source: String,
}

/// The dataset's coordinate reference system, metric, and where it came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Crs {
    /// The dataset's metric CRS, as WKT, PROJ string or authority code.
    pub definition: String,
    /// Where it came from: the DEM's CRS, or for geographic DEMs the local frame built from it.
    pub note: String,
}

/// The DEM: f32 heights in metres, sampled at grid vertices `spacing_m` apart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeightLayer {
    /// File name of the height pack, in the dataset folder.
    pub pack: String,
    /// Distance between level-0 samples, metres.
    pub spacing_m: f64,
    /// The heights' tile quadtree (`Sampling::Vertex`), shared by the validity mask.
    pub pyramid: Pyramid,
    /// Lowest height sample of the dataset, metres: the bound of a tile whose own range is unknown.
    pub min_m: f32,
    /// Highest height sample of the dataset, metres: the bound of a tile whose own range is unknown.
    pub max_m: f32,
    /// The step every height was rounded to when the dataset was built, metres (a power of two:
    /// each is exactly a multiple of it, within half a step of the source's warped value); absent
    /// when the heights are stored exactly as the source gave them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_m: Option<f32>,
    /// Samples with no source value that were filled: voids and nodata in the source, and, for a
    /// reprojected DEM, the grid's corners beyond the source's edge. Equals the zeros of the mask.
    pub filled_samples: u64,
    /// A pack of the same pyramid with 1 where the source had a value, 0 where it was filled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valid_mask_pack: Option<String>,
}

/// A layer of cell-area texels (imagery, land cover) over the DEM's pixel-area extent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellLayer {
    /// File name of the layer's pack, in the dataset folder.
    pub pack: String,
    /// Texel edge at level 0, metres.
    pub texel_m: f64,
    /// The layer's tile quadtree (`Sampling::Cell`), in texels of this layer.
    pub pyramid: Pyramid,
    /// Mips stored per tile.
    pub mips: u32,
    /// What the texels hold, e.g. "rgba8 srgb".
    pub format: String,
    /// The source file, for the record.
    pub source: String,
}

/// The land cover: an LCC quadtree (`crate::dataset::lcc`) whose `layer.pyramid` has exactly `LCC_LEVELS`
/// levels, level 1 the source's texels; `layer.texel_m` is level 0's texel, half the source's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandcoverLayer {
    /// Pack, texel size and pyramid, as for any cell layer (flattened into the same TOML table).
    #[serde(flatten)]
    pub layer: CellLayer,
    /// The word width and palette of the texels: what turns a stored word back into a code.
    pub coding: LccCoding,
    /// The classification scheme's name (e.g. "nc", "nlcd").
    pub scheme: String,
    /// The classes of the scheme. Codes absent here are "no class".
    pub classes: Vec<ClassName>,
    /// The code written where the source had no data.
    pub nodata_code: u8,
}

impl Manifest {
    /// CRS coordinates of the south-west corner of the DEM's pixel-area extent.
    pub fn corner_m(&self) -> [f64; 2] {
        let half = 0.5 * self.height.spacing_m;
        [self.origin_m[0] - half, self.origin_m[1] - half]
    }

    /// Size of the pixel-area extent, metres.
    pub fn extent_m(&self) -> [f64; 2] {
        self.height.pyramid.size.map(|n| f64::from(n) * self.height.spacing_m)
    }

    /// Checks the numbers the readers compute with, before they do, naming the first field wrong:
    /// positive, finite spacings; each pyramid sampled as its layer is, its tiles within
    /// `MAX_TILE_EXTENT` (`Pyramid::check_tiles`), and as many levels as `Pyramid::new` gives (land
    /// cover's LCC quadtree has its own, checked with its coding); imagery's mips down to no less
    /// than 1 texel. Unchecked, a level count or mips shifted sizes past 32 bits, a tile of 0
    /// divided by zero, a border doubled past u32.
    pub fn check_numbers(&self) -> Result<(), String> {
        let metres = |field: &str, value: f64| match value.is_finite() && value > 0.0 {
            true => Ok(()),
            false => Err(format!("{field} = {value}: must be a positive, finite number of metres")),
        };
        let pyramid = |layer: &str, p: &Pyramid, sampling: Sampling, own_levels: bool| {
            if p.sampling != sampling {
                return Err(format!(
                    "{layer}.pyramid.sampling = {:?}: {layer} is {sampling:?}-sampled",
                    p.sampling
                ));
            }
            p.check_tiles().map_err(|(field, reason)| format!("{layer}.pyramid.{field} = {reason}"))?;
            let levels = Pyramid::new(p.size, p.tile, p.border, sampling).levels;
            if !own_levels && p.levels != levels {
                let [w, h] = p.size;
                let tile = p.tile;
                return Err(format!(
                    "{layer}.pyramid.levels = {}: {w} × {h} in tiles of {tile} take {levels}",
                    p.levels
                ));
            }
            Ok(())
        };
        metres("height.spacing_m", self.height.spacing_m)?;
        pyramid("height", &self.height.pyramid, Sampling::Vertex, false)?;
        if let Some(l) = &self.imagery {
            metres("imagery.texel_m", l.texel_m)?;
            pyramid("imagery", &l.pyramid, Sampling::Cell, false)?;
            let (extent, mips) = (l.pyramid.tile_extent(), l.mips);
            let most = extent.ilog2() + 1;
            if !(1..=most).contains(&mips) {
                return Err(format!("imagery.mips = {mips}: tiles of {extent} texels have 1 to {most}"));
            }
        }
        if let Some(l) = &self.landcover {
            metres("landcover.texel_m", l.layer.texel_m)?;
            pyramid("landcover", &l.layer.pyramid, Sampling::Cell, true)?;
        }
        Ok(())
    }
}

/// One class of the land-cover scheme as the manifest records it, from the class table.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassName {
    /// The source's land-cover code of the class.
    pub code: u8,
    /// The class's name in the scheme's class table, e.g. "forest".
    pub name: String,
}
