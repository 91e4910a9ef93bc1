//! How it works: the dataset's place on the Earth (`terramp::earth::EarthFrame`), read from its
//! CRS and checked against PROJ before it is recorded. The projection's method and parameters and
//! the datum's ellipsoid come from GDAL's reading of the CRS; the datum's step to WGS 84 is the one
//! PROJ takes from the CRS to EPSG:4978 (geocentric WGS 84): the frame is tried with no step, then
//! with the datum's TOWGS84 Helmert parameters, and the first whose positions agree with PROJ's
//! within `AGREE_M` on a lattice over the grid's extent, at the DEM's lowest and highest heights,
//! is kept. A CRS whose projection the runtime does not know, or whose step PROJ makes otherwise
//! (a grid shift), gets no frame: the dataset is still built, flat, and the reason is printed.
//!
//! Heights: a DEM's heights are taken to be above EGM96 (SRTM's and GLOBE's are; NED's NAVD88
//! lies within about a metre of it across the conterminous US; a GeoTIFF rarely says), and the
//! frame carries EGM96's undulation over the dataset (`GeoidLattice`): the nodes of PROJ's 15′
//! EGM96 grid that cover it (PROJ's values at them), interpolated as PROJ does, checked against
//! PROJ at `GEOID_CHECKS` points and the largest difference recorded. Where PROJ has no EGM96 grid, heights stay ellipsoidal and
//! the frame says so.

use anyhow::{Context, Result};
use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use glam::DVec3;
use terramp::dataset::HeightLayer;
use terramp::earth::{DatumShift, EarthFrame, Ellipsoid, GeoidLattice, Projection};

use super::frame::Grid;
use super::gdal_ffi;

/// How far the recorded frame may lie from PROJ at any lattice point, metres.
const AGREE_M: f64 = 0.001;
/// The geoid heights are taken to be above: EGM96 height (EPSG:5773) on WGS 84.
const GEOID_CRS: &str = "EPSG:4326+5773";
/// EGM96's grid step in PROJ (`us_nga_egm96_15`), degrees: the lattice copies its nodes.
const GEOID_STEP_DEG: f64 = 0.25;
/// Random points at which the geoid lattice is checked against PROJ.
const GEOID_CHECKS: usize = 500;
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
fn earth_frame(srs: &SpatialRef, grid: &Grid, heights_m: [f64; 2]) -> Result<Result<EarthFrame, String>> {
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
            heights: String::new(),
            geoid: None,
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
            let geoid = geoid_lattice(&frame, grid)?;
            let heights = match &geoid {
                Some(g) => format!(
                    "the DEM's heights, taken as above {}: the frame adds its undulation ({} × {} nodes \
                     every {}°, within {:.1e} m of PROJ at {GEOID_CHECKS} points)",
                    g.name, g.size[0], g.size[1], g.step_deg, g.interpolation_error_m
                ),
                None => {
                    "the DEM's heights, taken as heights above the ellipsoid: PROJ has no EGM96 grid here"
                        .to_owned()
                }
            };
            return Ok(Ok(EarthFrame { datum_note, heights, geoid, ..frame }));
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

/// `points` (x, y, z in `from`, traditional GIS order) in `to`, by PROJ; `None` where PROJ has no
/// operation between them.
fn proj_transform(from: &SpatialRef, to: &SpatialRef, points: &[[f64; 3]]) -> Result<Option<Vec<[f64; 3]>>> {
    let (mut from, mut to) = (from.clone(), to.clone());
    from.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    to.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let Ok(transform) = CoordTransform::new(&from, &to) else { return Ok(None) };
    let [mut xs, mut ys, mut zs] = [0, 1, 2].map(|k| points.iter().map(|p| p[k]).collect::<Vec<f64>>());
    transform.transform_coords(&mut xs, &mut ys, &mut zs).context("transforming by PROJ")?;
    Ok(Some((0..points.len()).map(|i| [xs[i], ys[i], zs[i]]).collect()))
}

/// PROJ's WGS 84 Earth-centred positions (EPSG:4978) of `points` (x, y in `srs`, height).
fn to_ecef(srs: &SpatialRef, points: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
    let ecef = SpatialRef::from_epsg(4978).context("EPSG:4978")?;
    proj_transform(srs, &ecef, points)?.context("PROJ has no operation to EPSG:4978")
}

/// EGM96's undulation (metres) at each (latitude, longitude) in degrees, by PROJ; `None` where
/// PROJ has no EGM96 grid (it then leaves every height unchanged).
fn egm96_undulations(lat_lon_deg: &[[f64; 2]]) -> Result<Option<Vec<f64>>> {
    let geoid = SpatialRef::from_definition(GEOID_CRS).context(GEOID_CRS)?;
    let ellipsoidal = SpatialRef::from_epsg(4979).context("EPSG:4979")?;
    let points: Vec<[f64; 3]> = lat_lon_deg.iter().map(|&[lat, lon]| [lon, lat, 0.0]).collect();
    let heights = proj_transform(&geoid, &ellipsoidal, &points)
        .ok()
        .flatten()
        .map(|p| p.iter().map(|q| q[2]).collect());
    Ok(heights.filter(|h: &Vec<f64>| h.iter().any(|&z| z != 0.0)))
}

/// EGM96's grid nodes covering `grid` (a node's margin all round), by PROJ, checked against PROJ
/// at `GEOID_CHECKS` points; `None` without the grid.
fn geoid_lattice(frame: &EarthFrame, grid: &Grid) -> Result<Option<GeoidLattice>> {
    let extent = [grid.east_m() - grid.corner_m[0], grid.north_m() - grid.corner_m[1]];
    let lat_lon = |x: f64, y: f64| {
        let (lat, lon) = frame.geodetic(x, y);
        [lat.to_degrees(), lon.to_degrees()]
    };
    // The dataset's geographic bounds, from its edges densified: longitudes unwrapped about the
    // centre's, so that a dataset across the antimeridian has one west and one east.
    let centre_lon = lat_lon(grid.corner_m[0] + 0.5 * extent[0], grid.corner_m[1] + 0.5 * extent[1])[1];
    let (mut south, mut north, mut west, mut east) = (90.0f64, -90.0f64, f64::MAX, f64::MIN);
    let edge = 64;
    for k in 0..=edge {
        let f = f64::from(k) / f64::from(edge);
        for (u, v) in [(f, 0.0), (f, 1.0), (0.0, f), (1.0, f)] {
            let [lat, lon] = lat_lon(grid.corner_m[0] + u * extent[0], grid.corner_m[1] + v * extent[1]);
            let lon = centre_lon + (lon - centre_lon + 180.0).rem_euclid(360.0) - 180.0;
            (south, north, west, east) = (south.min(lat), north.max(lat), west.min(lon), east.max(lon));
        }
    }
    // A pole inside the grid lies inside its edges: the lattice then reaches it, all the way round
    // (its first and last columns the same meridian, so it wraps without a gap).
    for pole in [90.0f64, -90.0] {
        let [x, y] = frame.projection.forward(&frame.ellipsoid, pole.to_radians(), centre_lon.to_radians());
        let inside = (0.0..=extent[0]).contains(&(x - grid.corner_m[0]))
            && (0.0..=extent[1]).contains(&(y - grid.corner_m[1]));
        if inside {
            (south, north) = (south.min(pole), north.max(pole));
            (west, east) = (centre_lon - 180.0, centre_lon + 180.0);
        }
    }
    let step = GEOID_STEP_DEG;
    let (s, w) = ((south / step).floor() - 1.0, (west / step).floor() - 1.0);
    let (n, e) = ((north / step).ceil() + 1.0, (east / step).ceil() + 1.0);
    let e = e.min(w + 360.0 / step);
    let (s, n) = (s.max(-90.0 / step), n.min(90.0 / step));
    let size = [(e - w) as u32 + 1, (n - s) as u32 + 1];
    let nodes: Vec<[f64; 2]> = (0..size[1])
        .flat_map(|r| (0..size[0]).map(move |c| [(s + f64::from(r)) * step, (w + f64::from(c)) * step]))
        .collect();
    let Some(undulation) = egm96_undulations(&nodes)? else { return Ok(None) };
    let mut lattice = GeoidLattice {
        name: "EGM96 (PROJ's 15′ grid)".to_owned(),
        south_west_deg: [s * step, w * step],
        step_deg: step,
        size,
        undulation_m: undulation.iter().map(|&v| v as f32).collect(),
        interpolation_error_m: 0.0,
    };
    // Check points spread by a fixed additive recurrence (deterministic, no two alike).
    let checks: Vec<[f64; 2]> = (1..=GEOID_CHECKS)
        .map(|k| {
            let (u, v) =
                ((k as f64 * 0.754_877_666_246_692_7).fract(), (k as f64 * 0.569_840_290_998_053_3).fract());
            lat_lon(grid.corner_m[0] + u * extent[0], grid.corner_m[1] + v * extent[1])
        })
        .collect();
    let Some(truth) = egm96_undulations(&checks)? else { return Ok(None) };
    lattice.interpolation_error_m = checks
        .iter()
        .zip(&truth)
        .map(|(&[lat, lon], &n)| (lattice.undulation_at(lat.to_radians(), lon.to_radians()) - n).abs())
        .fold(0.0, f64::max);
    Ok(Some(lattice))
}
