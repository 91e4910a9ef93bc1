//! How it works: every input goes through two steps. `SourceRaster::open` opens a file with GDAL
//! and checks what the builder relies on (a file GDAL can read, a CRS, a north-up geotransform),
//! so a bad input fails before any work, with its path in the message. `GridRaster` then shows a
//! source on a target grid of the dataset: windows in grid space (x east, y north, south row
//! first), `NaN` wherever the source has no data.
//!
//! A source already on the target grid (same CRS, same pixel size, origin on a pixel corner) is
//! read as it is, so its values arrive bit for bit. Any other source is read through a warped VRT
//! (GDAL's reprojection, computed lazily block by block), so memory stays flat either way. A GDAL
//! handle is not thread-safe, so a grid raster holds one reader (the file opened, and its warped
//! VRT) per thread of the pool: each thread reads through its own, and the warps of the tile
//! writer's threads run side by side instead of queueing on one lock.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, Result, ensure};
use gdal::spatial_ref::{AxisMappingStrategy, SpatialRef};
use gdal::{Dataset, DatasetOptions, GdalOpenFlags, GeoTransform};
use terramp::dataset::Window;

use super::frame::Grid;
use super::gdal_ffi;

/// An opened input raster whose georeferencing has been checked.
pub struct SourceRaster {
    pub path: PathBuf,
    pub dataset: Dataset,
    pub srs: SpatialRef,
    /// GDAL's affine transform: CRS x = gt[0] + col·gt[1], CRS y = gt[3] + row·gt[5].
    pub geo_transform: GeoTransform,
    /// Columns and rows.
    pub size: [usize; 2],
}

impl SourceRaster {
    /// Opens `path`, the `role` input ("DEM", "imagery", "land cover"), and checks it.
    pub fn open(path: &Path, role: &str) -> Result<Self> {
        let what = || format!("{role} {}", path.display());
        let metadata = std::fs::metadata(path).with_context(|| format!("{}: cannot read it", what()))?;
        ensure!(metadata.is_file(), "{}: not a file", what());
        ensure!(metadata.len() > 0, "{}: the file is empty", what());
        let options = DatasetOptions {
            open_flags: GdalOpenFlags::GDAL_OF_RASTER | GdalOpenFlags::GDAL_OF_VERBOSE_ERROR,
            ..Default::default()
        };
        let dataset = Dataset::open_ex(path, options)
            .map_err(gdal_error)
            .with_context(|| format!("{}: not a raster GDAL can read (GeoTIFF expected)", what()))?;
        ensure!(dataset.raster_count() > 0, "{}: holds no raster band", what());
        let geo_transform = dataset
            .geo_transform()
            .map_err(|e| no_geotransform(&dataset, path, e))
            .with_context(|| format!("{}: has no georeferencing (no geotransform)", what()))?;
        check_north_up(&geo_transform).with_context(what)?;
        let mut srs = dataset.spatial_ref().map_err(gdal_error).with_context(|| {
            format!("{}: has no coordinate reference system; assign one (gdal_edit.py -a_srs)", what())
        })?;
        // Coordinates are always (east, north) here, whatever axis order the CRS declares.
        srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
        let (width, height) = dataset.raster_size();
        ensure!(width > 0 && height > 0, "{}: the raster is empty ({width} × {height})", what());
        Ok(Self { path: path.to_owned(), dataset, srs, geo_transform, size: [width, height] })
    }

    /// The same file opened again: another handle, for another thread.
    fn reopen(&self) -> Result<Dataset> {
        let options = DatasetOptions { open_flags: GdalOpenFlags::GDAL_OF_RASTER, ..Default::default() };
        Dataset::open_ex(&self.path, options)
            .map_err(gdal_error)
            .with_context(|| format!("{}: opening it again for another thread", self.path.display()))
    }

    /// The CRS extent of the pixel area: [west, south, east, north].
    pub fn extent(&self) -> [f64; 4] {
        let gt = &self.geo_transform;
        let (x0, x1) = (gt[0], gt[0] + self.size[0] as f64 * gt[1]);
        let (y0, y1) = (gt[3], gt[3] + self.size[1] as f64 * gt[5]);
        [x0.min(x1), y0.min(y1), x0.max(x1), y0.max(y1)]
    }

    /// Band `index`'s nodata value, if it has one.
    pub fn nodata(&self, index: usize) -> Result<Option<f64>> {
        Ok(self.band(index)?.no_data_value())
    }

    pub fn band(&self, index: usize) -> Result<gdal::raster::RasterBand<'_>> {
        self.dataset.rasterband(index).with_context(|| format!("{}: band {index}", self.path.display()))
    }
}

/// A GDAL error as its own message, without the Rust wrapper's decoration; when GDAL logged no
/// message, that it gave none (never its empty text).
pub fn gdal_error(error: gdal::errors::GdalError) -> anyhow::Error {
    use gdal::errors::GdalError;
    match error {
        GdalError::CplError { msg, .. } | GdalError::NullPointer { msg, .. } if !msg.trim().is_empty() => {
            anyhow::Error::msg(msg)
        }
        GdalError::CplError { class, number, .. } => {
            anyhow::anyhow!("GDAL gave no reason (CPL error class {class}, number {number})")
        }
        GdalError::NullPointer { method_name, .. } => {
            anyhow::anyhow!("GDAL gave no reason ({method_name} failed)")
        }
        other => anyhow::Error::new(other),
    }
}

/// Why `dataset` (the file at `path`) has no geotransform: GDAL's message when it logged one;
/// else which driver read the file, whatever its name says, and, when a sidecar beside it
/// (`<file>.aux.xml`) holds a geotransform, that this driver does not take it from there (GDAL's
/// PNM driver, for one, reads a world file only).
fn no_geotransform(dataset: &Dataset, path: &Path, error: gdal::errors::GdalError) -> anyhow::Error {
    if let gdal::errors::GdalError::CplError { msg, .. } = &error
        && !msg.trim().is_empty()
    {
        return gdal_error(error);
    }
    let driver = dataset.driver();
    let mut why =
        format!("GDAL reads the file with its {} driver ({})", driver.short_name(), driver.long_name());
    let sidecar = PathBuf::from(format!("{}.aux.xml", path.display()));
    if std::fs::read_to_string(&sidecar).is_ok_and(|xml| xml.contains("<GeoTransform>")) {
        why += &format!(", which does not take the geotransform in {}", sidecar.display());
    }
    let world = path.with_extension("wld");
    anyhow::anyhow!(
        "{why}: give the georeference in a world file ({}), or convert the file to a GeoTIFF with it \
         (gdal_translate -of GTiff -a_ullr WEST NORTH EAST SOUTH -a_srs CRS)",
        world.display()
    )
}

/// Rotated or sheared rasters would need a general affine resampling; GDAL's warper can make
/// them north-up first, and asking for that keeps this builder's grids simple.
fn check_north_up(gt: &GeoTransform) -> Result<()> {
    ensure!(
        gt[2] == 0.0 && gt[4] == 0.0,
        "rotated or sheared geotransform {gt:?} is not supported; make it north-up first (gdalwarp)"
    );
    ensure!(gt[1] != 0.0 && gt[5] != 0.0, "degenerate geotransform {gt:?} (zero pixel size)");
    Ok(())
}

/// How a warped source is interpolated onto the target grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Resampling {
    /// Continuous fields: heights, imagery.
    Bilinear,
    /// Codes that must never be blended: classes, palette indices.
    Nearest,
}

/// How a grid raster reaches its source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// The source is on the grid: read texel for texel.
    Direct,
    /// Reprojected or resampled by GDAL's warper.
    Warped,
}

/// GDAL state behind the lock. Field order is drop order: the warped VRT uses the source.
struct Reader {
    warped: Option<Dataset>,
    source: Dataset,
}

/// A source seen on a target grid, read window by window.
pub struct GridRaster {
    /// One per thread of rayon's pool (`rayon::current_thread_index`); other threads share the first.
    readers: Vec<Mutex<Reader>>,
    pub path: PathBuf,
    pub grid: Grid,
    pub access: Access,
    /// Band numbers (1-based) of the dataset that is read.
    bands: Vec<usize>,
    /// Per band, the value that means "no data" in the dataset that is read.
    nodata: Vec<Option<f64>>,
    /// Dataset column and row of the grid's north-west texel.
    offset: [i64; 2],
    /// Columns and rows of the dataset that is read.
    size: [i64; 2],
}

impl GridRaster {
    /// Shows `bands` of `source` on `grid`, whose CRS is `grid_srs`. `honour_nodata` false reads
    /// the source as if it had no nodata value (used to find where its footprint ends).
    pub fn new(
        source: SourceRaster,
        grid: &Grid,
        grid_srs: &SpatialRef,
        bands: &[usize],
        resampling: Resampling,
        honour_nodata: bool,
    ) -> Result<Self> {
        let path = source.path.clone();
        // Reading each band's nodata checks that the band exists, before any work.
        let nodata = bands.iter().map(|&b| source.nodata(b)).collect::<Result<Vec<_>>>()?;
        let threads = rayon::current_num_threads().max(1);
        let mut handles = (1..threads).map(|_| source.reopen()).collect::<Result<Vec<_>>>()?;
        if honour_nodata && let Some(offset) = aligned_offset(&source, grid, grid_srs) {
            let size = source.size.map(|n| n as i64);
            handles.insert(0, source.dataset);
            let readers = handles.into_iter().map(|source| Mutex::new(Reader { warped: None, source }));
            return Ok(Self {
                readers: readers.collect(),
                path,
                grid: *grid,
                access: Access::Direct,
                bands: bands.to_vec(),
                nodata,
                offset,
                size,
            });
        }
        let source_nodata = honour_nodata && nodata.iter().any(Option::is_some);
        let args = warp_args(grid, grid_srs, resampling, source_nodata)?;
        handles.insert(0, source.dataset);
        let readers = handles
            .into_iter()
            .map(|source| {
                let warped = gdal_ffi::warped_vrt(&source, &args)
                    .map_err(anyhow::Error::msg)
                    .with_context(|| format!("{}: reprojecting onto the dataset grid", path.display()))?;
                Ok(Mutex::new(Reader { warped: Some(warped), source }))
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            readers,
            path,
            grid: *grid,
            access: Access::Warped,
            bands: bands.to_vec(),
            // The warp writes NaN wherever the source had no data or does not reach.
            nodata: vec![None; bands.len()],
            offset: [0, 0],
            size: grid.size.map(i64::from),
        })
    }

    /// The window's texels of every band, south row first; `NaN` where there is no data.
    pub fn read(&self, window: Window) -> Result<Vec<Vec<f64>>, String> {
        let slot = rayon::current_thread_index().unwrap_or(0) % self.readers.len();
        let reader = self.readers[slot].lock().map_err(|_| "a reader thread panicked".to_owned())?;
        let dataset = reader.warped.as_ref().unwrap_or(&reader.source);
        (0..self.bands.len())
            .map(|slot| self.read_band(dataset, slot, window))
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}: {e}", self.path.display()))
    }

    /// The window of the first band, as `f32`.
    pub fn read_f32(&self, window: Window) -> Result<Vec<f32>, String> {
        let mut bands = self.read(window)?;
        Ok(bands.swap_remove(0).into_iter().map(|v| v as f32).collect())
    }

    fn read_band(&self, dataset: &Dataset, slot: usize, window: Window) -> Result<Vec<f64>, String> {
        let (width, height) = (window.width as usize, window.height as usize);
        let mut out = vec![f64::NAN; width * height];
        // Grid rows run south to north, dataset rows north to south.
        let col0 = self.offset[0] + i64::from(window.x0);
        let row0 = self.offset[1] + i64::from(self.grid.size[1] - window.y0 - window.height);
        let (c0, c1) = (col0.max(0), (col0 + width as i64).min(self.size[0]));
        let (r0, r1) = (row0.max(0), (row0 + height as i64).min(self.size[1]));
        if c0 >= c1 || r0 >= r1 {
            return Ok(out);
        }
        let (w, h) = ((c1 - c0) as usize, (r1 - r0) as usize);
        let mut buffer = vec![0.0f64; w * h];
        let band = dataset.rasterband(self.bands[slot]).map_err(|e| gdal_error(e).to_string())?;
        band.read_into_slice((c0 as isize, r0 as isize), (w, h), (w, h), &mut buffer, None).map_err(|e| {
            format!(
                "reading band {} rows {r0}..{r1}: {} (truncated or corrupt file?)",
                self.bands[slot],
                gdal_error(e)
            )
        })?;
        let nodata = self.nodata[slot];
        for (j, row) in buffer.chunks_exact(w).enumerate() {
            let grid_row = height - 1 - (r0 - row0) as usize - j;
            let start = grid_row * width + (c0 - col0) as usize;
            for (texel, &value) in out[start..start + w].iter_mut().zip(row) {
                *texel = if Some(value) == nodata { f64::NAN } else { value };
            }
        }
        Ok(out)
    }
}

/// The dataset pixel of the grid's north-west texel, if `source` lies exactly on `grid`.
fn aligned_offset(source: &SourceRaster, grid: &Grid, grid_srs: &SpatialRef) -> Option<[i64; 2]> {
    let gt = &source.geo_transform;
    let same_size = |step: f64| (step - grid.pixel_m).abs() <= 1e-9 * grid.pixel_m;
    if source.srs != *grid_srs || gt[1] <= 0.0 || gt[5] >= 0.0 || !same_size(gt[1]) || !same_size(-gt[5]) {
        return None;
    }
    let col = (grid.corner_m[0] - gt[0]) / gt[1];
    let row = (gt[3] - grid.north_m()) / -gt[5];
    let whole = |v: f64| ((v - v.round()).abs() <= 1e-6).then_some(v.round() as i64);
    Some([whole(col)?, whole(row)?])
}

/// `gdalwarp` arguments for a VRT of exactly `grid`, in `Float32` with `NaN` for no data.
///
/// `NaN` comes from one of two ways. With `source_nodata` (the source's nodata honoured), the
/// warp's destination nodata is `NaN`, and it skips the source's nodata too. Without, the warp
/// has no destination nodata at all and starts from `NaN` (`INIT_DEST`), which only the source's
/// footprint overwrites: the same texels, on GDAL's unmasked kernels, which take half the time of
/// the masked ones that a destination nodata selects (GLOBE: 11 s against 20 s of CPU).
fn warp_args(
    grid: &Grid,
    grid_srs: &SpatialRef,
    resampling: Resampling,
    source_nodata: bool,
) -> Result<Vec<String>> {
    ensure!(!grid.size.contains(&0) && grid.pixel_m > 0.0, "empty target grid {grid:?}");
    let srs = grid_srs.to_wkt().context("writing the dataset CRS as WKT")?;
    let method = match resampling {
        Resampling::Bilinear => "bilinear",
        Resampling::Nearest => "near",
    };
    let mut args: Vec<String> =
        ["-of", "VRT", "-ot", "Float32", "-r", method, "-t_srs", &srs, "-te"].map(String::from).into();
    // `-te` and `-ts` together pin the grid exactly: extent and texel count, hence texel size.
    args.extend([grid.corner_m[0], grid.corner_m[1], grid.east_m(), grid.north_m()].map(|v| v.to_string()));
    args.extend(["-ts".to_owned(), grid.size[0].to_string(), grid.size[1].to_string()]);
    let nodata: &[&str] = if source_nodata {
        &["-dstnodata", "nan"]
    } else {
        &["-srcnodata", "None", "-dstnodata", "None", "-wo", "INIT_DEST=nan"]
    };
    args.extend(nodata.iter().map(|s| String::from(*s)));
    Ok(args)
}
