//! Where a dataset lies on the Earth (issue 44, first part): the builder records the CRS's
//! projection, ellipsoid and datum step in the manifest (`terramp::earth::EarthFrame`), and the
//! runtime's Earth-centred position (WGS 84, EPSG:4978) of a dataset point equals PROJ's (through
//! GDAL, here) within a centimetre at 10,000 random points of nc (NAD83 / North Carolina, Lambert
//! Conformal Conic), of zion (NAD83 / UTM zone 12N, Transverse Mercator), and of rainier and GLOBE's
//! tile G (geographic DEMs, which the builder moves to a local azimuthal equidistant frame), at
//! random heights between the DEM's lowest and highest.

#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use terramp::dataset::Dataset;
use terramp::earth::{DatumShift, Projection};
use terramp_testkit::TempDir;

use support::{build, build_nc, build_zion};
use terramp_testkit::shared_data;

const POINTS: usize = 10_000;
const TOLERANCE_M: f64 = 0.01;

/// The largest distance between the runtime's and PROJ's positions of `POINTS` random points.
fn worst_against_proj(dataset: &Dataset, seed: u64) -> f64 {
    let manifest = &dataset.manifest;
    let earth = manifest.earth.as_ref().expect("the builder places the dataset on the Earth");
    let [w, h] = manifest.extent_m();
    let half = 0.5 * manifest.height.spacing_m;
    let mut state = seed;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (lo, hi) = (f64::from(manifest.height.min_m), f64::from(manifest.height.max_m));
    let points: Vec<[f64; 3]> = (0..POINTS)
        .map(|_| {
            let x = manifest.origin_m[0] - half + next() * (w + 2.0 * half);
            let y = manifest.origin_m[1] - half + next() * (h + 2.0 * half);
            [x, y, lo + next() * (hi - lo)]
        })
        .collect();
    let mut source = SpatialRef::from_definition(&manifest.crs.definition).unwrap();
    source.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let mut ecef = SpatialRef::from_epsg(4978).unwrap();
    ecef.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let transform = CoordTransform::new(&source, &ecef).unwrap();
    let mut xs: Vec<f64> = points.iter().map(|p| p[0]).collect();
    let mut ys: Vec<f64> = points.iter().map(|p| p[1]).collect();
    let mut zs: Vec<f64> = points.iter().map(|p| p[2]).collect();
    transform.transform_coords(&mut xs, &mut ys, &mut zs).unwrap();
    points
        .iter()
        .enumerate()
        .map(|(i, &[x, y, h])| (earth.ecef_m(x, y, h) - glam::DVec3::new(xs[i], ys[i], zs[i])).length())
        .fold(0.0, f64::max)
}

#[test]
fn nc_and_zion_lie_where_proj_puts_them() {
    let tmp = TempDir::new("earth");
    let nc = build_nc(&tmp.path().join("nc"));
    let earth = nc.manifest.earth.as_ref().unwrap();
    assert!(matches!(earth.projection, Projection::LambertConformalConic2Sp { .. }), "{earth:?}");
    assert_eq!(earth.to_wgs84, DatumShift::None, "PROJ's NAD83 to WGS 84 step is the null one");
    let worst = worst_against_proj(&nc, 0x5eed_0001);
    eprintln!("nc: {earth:?}\n  worst against PROJ over {POINTS} points: {worst:.3e} m");
    assert!(worst < TOLERANCE_M, "nc: {worst} m");

    let zion = build_zion(&tmp.path().join("zion"));
    let earth = zion.manifest.earth.as_ref().unwrap();
    assert!(matches!(earth.projection, Projection::TransverseMercator { .. }), "{earth:?}");
    let worst = worst_against_proj(&zion, 0x5eed_0002);
    eprintln!("zion: {earth:?}\n  worst against PROJ over {POINTS} points: {worst:.3e} m");
    assert!(worst < TOLERANCE_M, "zion: {worst} m");
}

#[test]
fn geographic_dems_lie_where_proj_puts_them() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("earth-geographic");
    for (name, file, seed) in [
        ("rainier", "rainier/mt_rainier_90m.tif", 0x5eed_0003),
        ("globe", "globe/globe_g_30arcsec.tif", 0x5eed_0004),
    ] {
        let dem = data.join(file);
        let (dataset, _) = build(&tmp.path().join(name), &["--dem", dem.to_str().unwrap()]);
        let earth = dataset.manifest.earth.as_ref().unwrap();
        assert!(matches!(earth.projection, Projection::AzimuthalEquidistant { .. }), "{earth:?}");
        let worst = worst_against_proj(&dataset, seed);
        eprintln!("{name}: {earth:?}\n  worst against PROJ over {POINTS} points: {worst:.3e} m");
        assert!(worst < TOLERANCE_M, "{name}: {worst} m");
        std::fs::remove_dir_all(tmp.path().join(name)).unwrap();
    }
}
