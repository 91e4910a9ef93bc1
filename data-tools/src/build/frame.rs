//! How it works: the DEM decides the dataset's frame. A DEM in a projected metric CRS keeps its
//! CRS and its own grid: its pixel centres become the height samples, untouched. A DEM in
//! geographic degrees is moved to a local metric frame, an azimuthal equidistant projection
//! centred on it (distances from the centre are true, so even a continent-sized DEM keeps its
//! scale within a few percent), on a square grid whose spacing is the DEM's latitude step in
//! metres at its centre, covering the DEM's whole footprint.
//!
//! Cell layers (imagery, land cover) tile the same pixel-area extent at their source's native
//! pixel size, so a source already aligned with the DEM is copied texel for texel.

use anyhow::{Context, Result, bail, ensure};
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use terramp::dataset::Crs;

use super::gdal_ffi;
use super::raster::SourceRaster;

/// A north-up raster grid in the dataset CRS.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// CRS coordinates of the south-west corner of the pixel-area extent.
    pub corner_m: [f64; 2],
    /// Texel edge, metres.
    pub pixel_m: f64,
    /// Texels per axis.
    pub size: [u32; 2],
}

impl Grid {
    pub fn east_m(&self) -> f64 {
        self.corner_m[0] + f64::from(self.size[0]) * self.pixel_m
    }

    pub fn north_m(&self) -> f64 {
        self.corner_m[1] + f64::from(self.size[1]) * self.pixel_m
    }

    /// CRS coordinates of the centre of texel (0, 0), the south-west one.
    pub fn first_centre_m(&self) -> [f64; 2] {
        self.corner_m.map(|c| c + 0.5 * self.pixel_m)
    }

    /// The same extent covered by texels of `pixel_m` (the last ones may reach past it).
    fn resampled(&self, pixel_m: f64) -> Grid {
        // Tolerate float noise, so that 15000 m / 10 m is 1500 texels and not 1501.
        let count = |n: u32| (f64::from(n) * self.pixel_m / pixel_m - 1e-9).ceil().max(1.0) as u32;
        Grid { corner_m: self.corner_m, pixel_m, size: self.size.map(count) }
    }
}

/// The dataset's metric frame and its height grid.
pub struct Frame {
    pub srs: SpatialRef,
    pub crs: Crs,
    /// Height samples sit at this grid's texel centres.
    pub dem_grid: Grid,
}

impl Frame {
    pub fn from_dem(dem: &SourceRaster) -> Result<Self> {
        let path = dem.path.display();
        if dem.srs.is_projected() {
            Self::projected(dem).with_context(|| format!("DEM {path}"))
        } else if dem.srs.is_geographic() {
            Self::local(dem).with_context(|| format!("DEM {path}"))
        } else {
            bail!("DEM {path}: its CRS is neither projected nor geographic; reproject it first")
        }
    }

    fn projected(dem: &SourceRaster) -> Result<Self> {
        let metres_per_unit = dem.srs.linear_units();
        ensure!(
            (metres_per_unit - 1.0).abs() < 1e-12,
            "its CRS unit is {} ({metres_per_unit} m); datasets are metric: reproject it to metres first",
            dem.srs.linear_units_name().unwrap_or_default()
        );
        let gt = &dem.geo_transform;
        let [west, south, east, north] = dem.extent();
        // Square samples: a raster with oblong pixels is resampled at its finer step.
        let pixel_m = gt[1].abs().min(gt[5].abs());
        let count = |extent: f64| (extent / pixel_m - 1e-9).ceil() as u32;
        let dem_grid =
            Grid { corner_m: [west, south], pixel_m, size: [count(east - west), count(north - south)] };
        let name = dem.srs.name().unwrap_or_else(|| "unnamed".to_owned());
        let authority = dem.srs.authority().map(|a| format!(" ({a})")).unwrap_or_default();
        let crs = Crs {
            definition: dem.srs.to_wkt().context("writing its CRS as WKT")?,
            note: format!("the DEM's CRS, {name}{authority}"),
        };
        let mut srs = dem.srs.clone();
        srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
        Ok(Self { srs, crs, dem_grid })
    }

    fn local(dem: &SourceRaster) -> Result<Self> {
        let [west, south, east, north] = dem.extent();
        let degrees_per_unit = dem.srs.angular_units().to_degrees();
        let (lon_deg, lat_deg) =
            (0.5 * (west + east) * degrees_per_unit, 0.5 * (south + north) * degrees_per_unit);
        let mut srs =
            gdal_ffi::azimuthal_equidistant(&dem.srs, lat_deg, lon_deg).map_err(anyhow::Error::msg)?;
        srs.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
        let to_local = CoordTransform::new(&dem.srs, &srs).context("transforming to the local frame")?;
        let centre = [0.5 * (west + east), 0.5 * (south + north)];
        let pixel_m = step_m(&to_local, centre, dem.geo_transform[5].abs())?;
        // The footprint's edges curve in the local frame: densify them to bound it.
        let [x0, y0, x1, y1] =
            to_local.transform_bounds(&[west, south, east, north], 101).context("bounding its footprint")?;
        let count = |extent: f64| (extent / pixel_m).ceil() as u32;
        let dem_grid = Grid { corner_m: [x0, y0], pixel_m, size: [count(x1 - x0), count(y1 - y0)] };
        let source_name = dem.srs.name().unwrap_or_else(|| "geographic".to_owned());
        let crs = Crs {
            definition: srs.to_wkt().context("writing the local frame as WKT")?,
            note: format!(
                "local azimuthal equidistant frame (+proj=aeqd +lat_0={lat_deg} +lon_0={lon_deg}) derived \
                 from the DEM's geographic CRS {source_name}; spacing = its latitude step at the centre"
            ),
        };
        Ok(Self { srs, crs, dem_grid })
    }

    /// CRS coordinates of the south-west height sample.
    pub fn origin_m(&self) -> [f64; 2] {
        self.dem_grid.first_centre_m()
    }

    /// The grid a cell layer from `source` gets: the DEM's extent at the source's own pixel size.
    /// Fails when the source does not overlap the DEM at all (a wrong file, or a wrong CRS tag).
    pub fn cell_grid(&self, source: &SourceRaster) -> Result<Grid> {
        let path = source.path.display();
        let gt = &source.geo_transform;
        let (pixel_m, extent) = if source.srs == self.srs {
            (gt[1].abs().min(gt[5].abs()), source.extent())
        } else {
            let to_frame = CoordTransform::new(&source.srs, &self.srs)
                .with_context(|| format!("{path}: transforming to the dataset CRS"))?;
            let [west, south, east, north] = source.extent();
            let centre = [0.5 * (west + east), 0.5 * (south + north)];
            let pixel_m = step_m(&to_frame, centre, gt[5].abs())
                .with_context(|| format!("{path}: measuring its pixel size"))?;
            let extent = to_frame
                .transform_bounds(&source.extent(), 21)
                .with_context(|| format!("{path}: transforming its extent to the dataset CRS"))?;
            (pixel_m, extent)
        };
        let dem = &self.dem_grid;
        let [west, south, east, north] = extent;
        ensure!(
            west < dem.east_m() && east > dem.corner_m[0] && south < dem.north_m() && north > dem.corner_m[1],
            "{path}: does not overlap the DEM (its extent in the dataset CRS is {extent:?}, the DEM's is {:?})",
            [dem.corner_m[0], dem.corner_m[1], dem.east_m(), dem.north_m()]
        );
        ensure!(pixel_m > 0.0 && pixel_m.is_finite(), "{path}: bad pixel size {pixel_m}");
        Ok(dem.resampled(pixel_m))
    }
}

/// The length, in the target CRS of `transform`, of a north-south step of `step` source units
/// centred on `centre`.
fn step_m(transform: &CoordTransform, centre: [f64; 2], step: f64) -> Result<f64> {
    let mut x = [centre[0], centre[0]];
    let mut y = [centre[1] - 0.5 * step, centre[1] + 0.5 * step];
    transform.transform_coords(&mut x, &mut y, &mut []).context("transforming a pixel step")?;
    let length = (x[1] - x[0]).hypot(y[1] - y[0]);
    ensure!(length > 0.0 && length.is_finite(), "a pixel step transforms to {length} m");
    Ok(length)
}
