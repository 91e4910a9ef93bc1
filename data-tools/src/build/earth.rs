//! How it works: the dataset's place on the Earth (`terramp::earth::EarthFrame`), read from its
//! CRS and checked against PROJ before it is recorded. The projection's method and parameters and
//! the datum's ellipsoid come from GDAL's reading of the CRS; the datum's step to WGS 84 is the one
//! PROJ takes from the CRS to EPSG:4978 (geocentric WGS 84): the frame is tried with no step, then
//! with the datum's TOWGS84 Helmert parameters, and the first whose positions agree with PROJ's
//! within `AGREE_M` on a lattice over the grid's extent, at the DEM's lowest and highest heights,
//! is kept. A CRS whose projection the runtime does not know, or whose step PROJ makes otherwise
//! (a grid shift), gets no frame: the dataset is still built, flat, and the reason is printed.

use anyhow::{Context, Result};
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use glam::DVec3;
use terramp::dataset::HeightLayer;
use terramp::earth::{DatumShift, EarthFrame, Ellipsoid, Projection};

use super::frame::Grid;
use super::gdal_ffi;

/// How far the recorded frame may lie from PROJ at any lattice point, metres.
pub const AGREE_M: f64 = 0.001;
/// Lattice points per axis over the grid's extent.
const LATTICE: u32 = 9;

/// The frame of `frame`'s CRS over its grid with `height`'s range, or `None`, the reason printed.
pub fn place(frame: &super::frame::Frame, height: &HeightLayer) -> Result<Option<EarthFrame>> {
    let bounds_m = [f64::from(height.min_m), f64::from(height.max_m)];
    Ok(match earth_frame(&frame.srs, &frame.dem_grid, bounds_m)? {
        Ok(earth) => Some(earth),
        Err(reason) => {
            eprintln!("terramp-data: the dataset is not placed on the Earth: {reason}");
            None
        }
    })
}

/// The frame of `srs` over `grid` with heights `heights_m` (lowest, highest), or why there is
/// none.
pub fn earth_frame(srs: &SpatialRef, grid: &Grid, heights_m: [f64; 2]) -> Result<Result<EarthFrame, String>> {
    let Some(projection) = projection(srs)? else {
        let method = srs.get_attr_value("PROJECTION", 0).ok().flatten().unwrap_or_else(|| "none".to_owned());
        return Ok(Err(format!("its projection {method} has no mapping to the Earth yet")));
    };
    let a_m = srs.semi_major().context("reading the ellipsoid")?;
    let b_m = srs.semi_minor().context("reading the ellipsoid")?;
    let ellipsoid = Ellipsoid { a_m, inv_f: if a_m > b_m { a_m / (a_m - b_m) } else { 0.0 } };
    let datum = srs.get_attr_value("DATUM", 0).ok().flatten().unwrap_or_else(|| "its datum".to_owned());
    let mut shifts = vec![DatumShift::None];
    if let Some(p) = gdal_ffi::towgs84(srs).filter(|p| p.iter().any(|&v| v != 0.0)) {
        shifts.push(DatumShift::Helmert {
            translation_m: [p[0], p[1], p[2]],
            rotation_arcsec: [p[3], p[4], p[5]],
            scale_ppm: p[6],
        });
    }
    let points = lattice(grid, heights_m);
    let proj = to_ecef(srs, &points)?;
    for to_wgs84 in shifts {
        let frame = EarthFrame {
            projection,
            ellipsoid,
            to_wgs84,
            datum_note: String::new(),
            heights: "the DEM's heights, taken as heights above the ellipsoid: no geoid applied".to_owned(),
        };
        let worst_m = points
            .iter()
            .zip(&proj)
            .map(|(&[x, y, h], &p)| (frame.ecef_m(x, y, h) - DVec3::from(p)).length())
            .fold(0.0, f64::max);
        if worst_m <= AGREE_M {
            let step = match to_wgs84 {
                DatumShift::None => "none (its coordinates taken as WGS 84's)",
                DatumShift::Helmert { .. } => "its TOWGS84 Helmert transformation",
            };
            let datum_note = format!(
                "{datum} to WGS 84: {step}, as PROJ takes it to EPSG:4978; checked against PROJ at {} points, \
                 largest difference {worst_m:.1e} m",
                points.len()
            );
            return Ok(Ok(EarthFrame { datum_note, ..frame }));
        }
    }
    Ok(Err(format!(
        "PROJ's step from {datum} to WGS 84 is neither none nor its TOWGS84 Helmert transformation"
    )))
}

/// The runtime's projection of `srs`, if it has one.
fn projection(srs: &SpatialRef) -> Result<Option<Projection>> {
    if !srs.is_projected() {
        return Ok(None);
    }
    let method = srs.get_attr_value("PROJECTION", 0).context("reading the projection")?.unwrap_or_default();
    let param = |name: &str| -> Result<f64> {
        srs.get_proj_param(name)
            .with_context(|| format!("reading the projection's {name}"))?
            .with_context(|| format!("the projection has no {name}"))
    };
    Ok(Some(match method.as_str() {
        "Lambert_Conformal_Conic_2SP" => Projection::LambertConformalConic2Sp {
            lat_origin_deg: param("latitude_of_origin")?,
            lon_origin_deg: param("central_meridian")?,
            parallel_1_deg: param("standard_parallel_1")?,
            parallel_2_deg: param("standard_parallel_2")?,
            false_easting_m: param("false_easting")?,
            false_northing_m: param("false_northing")?,
        },
        "Transverse_Mercator" => Projection::TransverseMercator {
            lat_origin_deg: param("latitude_of_origin")?,
            lon_origin_deg: param("central_meridian")?,
            scale: param("scale_factor")?,
            false_easting_m: param("false_easting")?,
            false_northing_m: param("false_northing")?,
        },
        "Azimuthal_Equidistant" => Projection::AzimuthalEquidistant {
            lat_origin_deg: param("latitude_of_center")?,
            lon_origin_deg: param("longitude_of_center")?,
            false_easting_m: param("false_easting")?,
            false_northing_m: param("false_northing")?,
        },
        _ => return Ok(None),
    }))
}

/// A lattice over `grid`'s extent at both heights (x, y in its CRS, height).
fn lattice(grid: &Grid, heights_m: [f64; 2]) -> Vec<[f64; 3]> {
    let f = |k: u32| f64::from(k) / f64::from(LATTICE - 1);
    let mut points = Vec::new();
    for j in 0..LATTICE {
        for i in 0..LATTICE {
            let x = grid.corner_m[0] + f(i) * (grid.east_m() - grid.corner_m[0]);
            let y = grid.corner_m[1] + f(j) * (grid.north_m() - grid.corner_m[1]);
            points.extend(heights_m.map(|h| [x, y, h]));
        }
    }
    points
}

/// PROJ's WGS 84 Earth-centred positions (EPSG:4978) of `points` (x, y in `srs`, height).
pub fn to_ecef(srs: &SpatialRef, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
    let mut source = srs.clone();
    source.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let mut ecef = SpatialRef::from_epsg(4978).context("EPSG:4978")?;
    ecef.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let transform = CoordTransform::new(&source, &ecef).context("transforming to EPSG:4978")?;
    let (mut xs, mut ys, mut zs): (Vec<f64>, Vec<f64>, Vec<f64>) = (
        points.iter().map(|p| p[0]).collect(),
        points.iter().map(|p| p[1]).collect(),
        points.iter().map(|p| p[2]).collect(),
    );
    transform.transform_coords(&mut xs, &mut ys, &mut zs).context("transforming to EPSG:4978")?;
    Ok((0..points.len()).map(|i| [xs[i], ys[i], zs[i]]).collect())
}
