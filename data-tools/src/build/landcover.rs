//! How it works: land cover is copied code for code onto the DEM's extent at the source's own
//! pixel size: directly when it is aligned with the DEM's grid, else through GDAL's warper with
//! nearest-neighbour resampling, since blending class codes would invent classes. The source's
//! nodata becomes the class table's `nodata_code`. Those codes are stored losslessly in the
//! library's LCC quadtree (`terramp::dataset::lcc`), whose level 1 is this grid: a first pass over the
//! source counts every code, which gives the palette (and so the word width) and the texels whose
//! code is missing from the table (kept, they mean "no class", and reported, so a wrong
//! `--classes` shows in the build's summary); a second pass writes the 3 levels.

use std::path::Path;

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use terramp::classes::ClassTable;
use terramp::dataset::lcc::{CodeCounts, LccCoding, scan_codes, write_lcc_layer};
use terramp::dataset::{CellLayer, LandcoverLayer, Pyramid, Staging, Window};

use super::frame::{Frame, Grid};
use super::raster::{Access, GridRaster, Resampling, SourceRaster};

pub const LANDCOVER_PACK: &str = "landcover.pack";

/// A land-cover input, ready to be tiled.
pub struct Landcover {
    raster: GridRaster,
    table: ClassTable,
}

/// What the first pass found.
pub struct LandcoverScan {
    pub counts: CodeCounts,
    pub coding: LccCoding,
}

impl LandcoverScan {
    /// Texels whose code is neither in the table nor its nodata code.
    pub fn unknown_texels(&self, table: &ClassTable) -> u64 {
        self.counts
            .present()
            .filter(|&c| c != table.nodata_code && !table.contains(c))
            .map(|c| self.counts.texels[usize::from(c)])
            .sum()
    }
}

impl Landcover {
    pub fn open(path: &Path, classes: &str, frame: &Frame) -> Result<Self> {
        let table = ClassTable::load(classes).context("loading the land-cover class table")?;
        let source = SourceRaster::open(path, "land cover")?;
        let grid = frame.cell_grid(&source)?;
        let raster = GridRaster::new(source, &grid, &frame.srs, &[1], Resampling::Nearest, true)?;
        Ok(Self { raster, table })
    }

    pub fn grid(&self) -> &Grid {
        &self.raster.grid
    }

    pub fn access(&self) -> Access {
        self.raster.access
    }

    pub fn table(&self) -> &ClassTable {
        &self.table
    }

    /// The source's codes in `window` of the grid, south row first.
    pub fn codes(&self, window: Window) -> Result<Vec<u8>, String> {
        let nodata_code = self.table.nodata_code;
        Ok(self.raster.read(window)?[0].iter().map(|&v| code_of(v, nodata_code)).collect())
    }

    /// The first pass: every code of the source, and the LCC coding they need.
    pub fn scan(&self, bar: &ProgressBar) -> Result<LandcoverScan> {
        let counts = scan_codes(self.grid().size, &|w| self.codes(w), bar)
            .context("scanning the land cover's codes")?;
        let coding = LccCoding::for_codes(counts.present())
            .with_context(|| format!("{}: coding the land cover", self.raster.path.display()))?;
        Ok(LandcoverScan { counts, coding })
    }

    /// The second pass: the LCC quadtree, from the coding the scan found.
    pub fn write(
        &self,
        scan: &LandcoverScan,
        staging: &Staging,
        bar: &ProgressBar,
    ) -> Result<LandcoverLayer> {
        let coding = &scan.coding;
        let pyramid =
            write_lcc_layer(&staging.path(LANDCOVER_PACK), self.grid().size, coding, |w| self.codes(w), bar)
                .context("writing the land-cover pack")?;
        Ok(self.layer(pyramid, coding.clone()))
    }

    /// The manifest's land-cover layer, its LCC quadtree `pyramid` coded by `coding`.
    pub fn layer(&self, pyramid: Pyramid, coding: LccCoding) -> LandcoverLayer {
        LandcoverLayer {
            layer: CellLayer {
                pack: LANDCOVER_PACK.to_owned(),
                // Level 0 repeats each source texel on its 2 × 2 children.
                texel_m: 0.5 * self.grid().pixel_m,
                pyramid,
                mips: 1,
                format: coding.format_name(),
                source: self.raster.path.display().to_string(),
            },
            coding,
            scheme: self.table.scheme.clone(),
            classes: self.table.names(),
            nodata_code: self.table.nodata_code,
        }
    }
}

/// A source value as a class code: no data, or a value no `u8` code can carry, is `nodata_code`.
fn code_of(value: f64, nodata_code: u8) -> u8 {
    let code = value.round();
    if (0.0..=255.0).contains(&code) { code as u8 } else { nodata_code }
}
