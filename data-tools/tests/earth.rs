//! Where a dataset lies on the Earth (issue 44, first part): the builder records the CRS's
//! projection, ellipsoid and datum step in the manifest (`terramp::earth::EarthFrame`), and the
//! runtime's Earth-centred position (WGS 84, EPSG:4978) of a dataset point equals PROJ's (through
//! GDAL, here) within a centimetre at 10,000 random points of nc (NAD83 / North Carolina, Lambert
//! Conformal Conic), of zion (NAD83 / UTM zone 12N, Transverse Mercator), and of rainier and GLOBE's
//! tile G (geographic DEMs, which the builder moves to a local azimuthal equidistant frame), at
//! random heights between the DEM's lowest and highest. The heights are above EGM96 (the frame's
//! geoid lattice); PROJ's reference adds EGM96's undulation from its own grid at each point, so
//! the bound is a centimetre plus the lattice's recorded interpolation error, which must itself be
//! under a centimetre on the three local datasets.

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
    let worst = worst_against_proj_m(dataset, seed);
    let earth = dataset.manifest.earth.as_ref().unwrap();
    let geoid = earth.geoid.as_ref().expect("heights above EGM96");
    eprintln!(
        "{}: {:?}\n  {}\n  geoid lattice {:?} every {}°, interpolation error {:.2e} m\n  worst against PROJ over \
         {POINTS} points: {worst:.3e} m",
        dataset.manifest.name,
        earth.projection,
        earth.heights,
        geoid.size,
        geoid.step_deg,
        geoid.interpolation_error_m
    );
    assert!(worst < TOLERANCE_M + geoid.interpolation_error_m, "{}: {worst} m", dataset.manifest.name);
    worst
}

fn worst_against_proj_m(dataset: &Dataset, seed: u64) -> f64 {
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
    // PROJ's EGM96 undulation at each point (EGM96 height on WGS 84 to ellipsoidal height).
    let mut geoid = SpatialRef::from_definition("EPSG:4326+5773").unwrap();
    geoid.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let mut ellipsoidal = SpatialRef::from_epsg(4979).unwrap();
    ellipsoidal.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let lat_lon: Vec<(f64, f64)> = points.iter().map(|&[x, y, _]| earth.geodetic(x, y)).collect();
    let mut lons: Vec<f64> = lat_lon.iter().map(|p| p.1.to_degrees()).collect();
    let mut lats: Vec<f64> = lat_lon.iter().map(|p| p.0.to_degrees()).collect();
    let mut undulation = vec![0.0; POINTS];
    CoordTransform::new(&geoid, &ellipsoidal)
        .unwrap()
        .transform_coords(&mut lons, &mut lats, &mut undulation)
        .unwrap();
    assert!(undulation.iter().any(|&n| n != 0.0), "PROJ must have EGM96's grid (proj-data)");
    let mut xs: Vec<f64> = points.iter().map(|p| p[0]).collect();
    let mut ys: Vec<f64> = points.iter().map(|p| p[1]).collect();
    let mut zs: Vec<f64> = points.iter().zip(&undulation).map(|(p, n)| p[2] + n).collect();
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
    worst_against_proj(&nc, 0x5eed_0001);
    assert!(earth.geoid.as_ref().unwrap().interpolation_error_m < TOLERANCE_M);

    let zion = build_zion(&tmp.path().join("zion"));
    let earth = zion.manifest.earth.as_ref().unwrap();
    assert!(matches!(earth.projection, Projection::TransverseMercator { .. }), "{earth:?}");
    worst_against_proj(&zion, 0x5eed_0002);
    assert!(earth.geoid.as_ref().unwrap().interpolation_error_m < TOLERANCE_M);
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
        worst_against_proj(&dataset, seed);
        assert!(earth.geoid.as_ref().unwrap().interpolation_error_m < TOLERANCE_M, "{name}");
        std::fs::remove_dir_all(tmp.path().join(name)).unwrap();
    }
}

/// EGM96 as the frame carries it against NGA's published test values of EGM96 (its README's
/// `outintpt.dat`, computed from the spherical harmonics, not from a grid) at three named places:
/// each the centre of a small geographic DEM made here, so that the frame's own inverse and
/// lattice are what is judged. PROJ's grid is 15′ and bilinear: within 0.1 m.
#[test]
fn egm96_at_named_places() {
    let tmp = TempDir::new("earth-geoid");
    let places = [
        ("St. Louis, Missouri", 38.628_155, -90.220_845, -31.628),
        ("Mongolia", 46.874_319, 102.448_729, -43.575),
        ("the Northern Territory, Australia", -23.617_446, 133.874_712, 15.871),
    ];
    for (k, (name, lat, lon, published_m)) in places.into_iter().enumerate() {
        let (n, step) = (64usize, 0.01);
        let transform = [lon - 0.5 * n as f64 * step, step, 0.0, lat + 0.5 * n as f64 * step, 0.0, -step];
        let dem = support::write_geotiff(
            &tmp.path().join(format!("dem{k}.tif")),
            [n, n],
            vec![100.0f32; n * n],
            transform,
            4326,
            None,
        );
        let (dataset, _) = build(&tmp.path().join(format!("place{k}")), &["--dem", dem.to_str().unwrap()]);
        let earth = dataset.manifest.earth.as_ref().unwrap();
        // The local frame is centred on the DEM: the place is its origin.
        let (lat2, lon2) = earth.geodetic(0.0, 0.0);
        assert!((lat2.to_degrees() - lat).abs() < 1e-9 && (lon2.to_degrees() - lon).abs() < 1e-9, "{name}");
        let undulation = earth.geoid.as_ref().unwrap().undulation_at(lat2, lon2);
        eprintln!("{name}: EGM96 {undulation:.3} m, NGA {published_m} m");
        assert!((undulation - published_m).abs() < 0.1, "{name}: {undulation} against {published_m}");
    }
}
