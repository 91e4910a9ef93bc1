//! How it works: land cover is copied code for code onto the DEM's extent at the source's own
//! pixel size: directly when it is aligned with the DEM's grid, else through GDAL's warper with
//! nearest-neighbour resampling, since blending class codes would invent classes. The source's
//! nodata becomes the class table's `nodata_code`. Codes missing from the table are kept (they
//! mean "no class") and counted, so a wrong `--classes` shows in the build's summary.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use terramp::classes::ClassTable;
use terramp::dataset::{CellLayer, LandcoverLayer, LayerSpec, Staging, Window, write_layer};

use super::frame::{Frame, Grid};
use super::raster::{Access, GridRaster, Resampling, SourceRaster};

pub const LANDCOVER_PACK: &str = "landcover.pack";

/// A land-cover input, ready to be tiled.
pub struct Landcover {
    raster: GridRaster,
    table: ClassTable,
    /// Level-0 texels whose code is neither in the table nor its nodata code.
    unknown_texels: AtomicU64,
}

impl Landcover {
    pub fn open(path: &Path, classes: &str, frame: &Frame) -> Result<Self> {
        let table = ClassTable::load(classes).context("loading the land-cover class table")?;
        let source = SourceRaster::open(path, "land cover")?;
        let grid = frame.cell_grid(&source)?;
        let raster = GridRaster::new(source, &grid, &frame.srs, &[1], Resampling::Nearest, true)?;
        Ok(Self { raster, table, unknown_texels: AtomicU64::new(0) })
    }

    pub fn grid(&self) -> &Grid {
        &self.raster.grid
    }

    pub fn access(&self) -> Access {
        self.raster.access
    }

    pub fn scheme(&self) -> &str {
        &self.table.scheme
    }

    pub fn unknown_texels(&self) -> u64 {
        self.unknown_texels.load(Ordering::Relaxed)
    }

    pub fn write(&self, staging: &Staging, bar: &ProgressBar) -> Result<LandcoverLayer> {
        let grid = self.grid();
        let spec = LayerSpec::landcover(grid.size);
        let nodata_code = self.table.nodata_code;
        let codes = |window: Window| -> Result<Vec<u8>, String> {
            let codes: Vec<u8> =
                self.raster.read(window)?[0].iter().map(|&v| code_of(v, nodata_code)).collect();
            // Level-0 windows of a borderless layer do not overlap, so each texel counts once.
            let unknown = codes.iter().filter(|&&c| c != nodata_code && !self.table.contains(c)).count();
            self.unknown_texels.fetch_add(unknown as u64, Ordering::Relaxed);
            Ok(codes)
        };
        write_layer(&staging.path(LANDCOVER_PACK), &spec, codes, bar)
            .context("writing the land-cover pack")?;
        Ok(LandcoverLayer {
            layer: CellLayer {
                pack: LANDCOVER_PACK.to_owned(),
                texel_m: grid.pixel_m,
                pyramid: spec.pyramid,
                mips: 1,
                format: "r8 class codes".to_owned(),
                source: self.raster.path.display().to_string(),
            },
            scheme: self.table.scheme.clone(),
            classes: self.table.names(),
            nodata_code,
        })
    }
}

/// A source value as a class code: no data, or a value no `u8` code can carry, is `nodata_code`.
fn code_of(value: f64, nodata_code: u8) -> u8 {
    let code = value.round();
    if (0.0..=255.0).contains(&code) { code as u8 } else { nodata_code }
}
