//! `terramp-data build` end to end: real GeoTIFFs from the shared data in, datasets out, opened
//! with the runtime library and compared with what GDAL reads from the sources.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::Path;

use gdal::spatial_ref::{AxisMappingStrategy, CoordTransform, SpatialRef};
use support::{build, gdal_band, height_image, level_image, mask_image, north_first, number_before};
use terramp::dataset::{Dataset, DatasetError, ImageryFormat, PackError, TileId};
use terramp_testkit::{TempDir, shared_data};

/// Truth from `gdallocationinfo -valonly nc/elev_ned_30m.tif COL ROW`: (row, col, metres).
const NC_KNOWN: [(u32, u32, f64); 5] = [
    (0, 0, 145.300857543945),
    (449, 499, 86.2446060180664),
    (100, 250, 109.59587097168),
    (225, 37, 113.386207580566),
    (312, 401, 106.712852478027),
];
/// Truth from `gdallocationinfo -valonly rainier/mt_rainier_90m.tif COL ROW`.
const RAINIER_KNOWN: [(u32, u32, f64); 4] =
    [(600, 600, 1849.0), (1200, 1200, 1115.0), (150, 220, 2496.0), (900, 333, 1392.0)];

/// The land cover's codes at LCC `level` (0 or 1: one code per texel), south row first, checked
/// across tiles.
fn lcc_codes(dataset: &Dataset, level: u32) -> Vec<u8> {
    let (layer, coding) = (dataset.landcover.as_ref().unwrap(), dataset.lcc_coding().unwrap());
    let words = level_image(&layer.pyramid, level, |id| dataset.landcover_words(id).unwrap());
    words.iter().map(|&index| coding.code_of(index).expect("a palette index")).collect()
}

#[test]
fn nc_trio_is_copied_exactly_and_tiles_agree() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("nc");
    let nc = |file: &str| data.join("nc").join(file).to_str().unwrap().to_owned();
    let (dem, imagery, landuse) = (nc("elev_ned_30m.tif"), nc("landsat_multiband.tif"), nc("landuse_r.tif"));
    let (dataset, _) = build(
        &tmp.path().join("nc"),
        &[
            "--dem",
            &dem,
            "--imagery",
            &imagery,
            "--bands",
            "3,2,1",
            "--landcover",
            &landuse,
            "--classes",
            "nc",
        ],
    );
    let manifest = &dataset.manifest;
    assert_eq!(manifest.origin_m, [630_015.0, 215_015.0], "south-west sample centre");
    assert_eq!((manifest.height.spacing_m, manifest.height.pyramid.size), (30.0, [500, 450]));
    assert_eq!((manifest.height.filled_samples, manifest.height.valid_mask_pack.as_deref()), (0, None));

    // Known pixels, through the runtime reader (grid y runs north: y = rows - 1 - row).
    for (row, col, truth) in NC_KNOWN {
        let height = dataset.height_sample(0, col, 449 - row).unwrap();
        assert_eq!(height, truth as f32 as f64, "row {row}, col {col}");
    }
    // Every sample of level 0, and every level's tile borders.
    let (source, size) = gdal_band(Path::new(&dem));
    let level0 = height_image(&dataset, 0);
    for (k, &height) in level0.iter().enumerate() {
        let (x, y) = ((k % 500) as u32, (k / 500) as u32);
        assert_eq!(height, north_first(&source, size, x, y) as f32, "sample ({x}, {y})");
    }
    let valid = source.iter().map(|&h| h as f32);
    let range = valid.fold([f32::MAX, f32::MIN], |[lo, hi], h| [lo.min(h), hi.max(h)]);
    assert_eq!([manifest.height.min_m, manifest.height.max_m], range);
    for level in 1..dataset.height.pyramid.levels {
        height_image(&dataset, level);
    }

    // Land cover is aligned (10 m on the 30 m DEM's extent): copied code for code, nodata too, as
    // LCC level 1 (data-tools/tests/lcc.rs checks all 3 levels).
    let landcover = manifest.landcover.as_ref().unwrap();
    let layer = &landcover.layer;
    assert_eq!((layer.texel_m, layer.pyramid.size_at(1)), (5.0, [1500, 1350]));
    let codes = lcc_codes(&dataset, 1);
    let (source, size) = gdal_band(Path::new(&landuse));
    let mut nodata = 0;
    for (k, &code) in codes.iter().enumerate() {
        let (x, y) = ((k % 1500) as u32, (k / 1500) as u32);
        assert_eq!(f64::from(code), north_first(&source, size, x, y), "texel ({x}, {y})");
        nodata += usize::from(code == 255);
    }
    assert!(nodata > 1000, "the source's nodata (255) must survive, found {nodata}");

    // Imagery: 28.5 m texels, reprojected; no data is transparent but never black.
    let imagery = manifest.imagery.as_ref().unwrap();
    assert_eq!((imagery.texel_m, imagery.pyramid.size), (28.5, [527, 474]));
    let extent = imagery.pyramid.tile_extent() as usize;
    let pack = dataset.imagery.as_ref().unwrap();
    let texels = level_image(&imagery.pyramid, 0, |id| {
        pack.tile_bytes(id).unwrap()[..extent * extent * 4]
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect()
    });
    let holes: Vec<&[u8; 4]> = texels.iter().filter(|t| t[3] == 0).collect();
    assert!(holes.len() > texels.len() / 50, "the Landsat scene does not cover the whole DEM");
    assert!(holes.iter().all(|t| t[..3] == holes[0][..3] && t[..3] != [0, 0, 0]), "{:?}", holes[0]);
    let mean_grey = texels.iter().filter(|t| t[3] == 255).map(|t| f64::from(t[1])).sum::<f64>()
        / (texels.len() - holes.len()) as f64;
    assert!(
        (40.0..200.0).contains(&mean_grey),
        "stretched imagery should be mid-grey on average: {mean_grey}"
    );
}

/// Least PSNR of nc's covered level-0 texels in BC7 and in BC1 against the plain build, dB: 2 dB
/// under what the encoder gives (35.5 and 29.5 dB, docs/building.md), room for another release of
/// it; a lost texel or a channel swapped falls far below.
const BC7_MIN_DB: f64 = 33.5;
const BC1_MIN_DB: f64 = 27.5;
/// Most a texel's alpha may move in BC7 (lossy in every channel), levels of 255: holes stay
/// under 8 and covered texels over 247; BC1 keeps alpha exactly (punch-through, 0 or 255).
const BC7_MAX_ALPHA_ERROR: u8 = 8;

/// nc's Landsat scene, which leaves a corner of the DEM uncovered, stored in BC7 and BC1 blocks:
/// each decodes close to the plain build, with its holes where the plain one has them.
#[test]
fn nc_imagery_in_blocks_keeps_its_holes() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("nc-blocks");
    let nc = |file: &str| data.join("nc").join(file).to_str().unwrap().to_owned();
    let (dem, imagery) = (nc("elev_ned_30m.tif"), nc("landsat_multiband.tif"));
    let build_as = |format: &str| {
        let args = ["--dem", &dem, "--imagery", &imagery, "--bands", "3,2,1", "--imagery-format", format];
        build(&tmp.path().join(format), &args).0
    };
    let level0 = |dataset: &Dataset| {
        let layer = dataset.imagery.as_ref().unwrap();
        let extent = layer.pyramid.tile_extent() as usize;
        level_image(&layer.pyramid, 0, |id| {
            let texels = layer.tile_texels(id).unwrap();
            texels[..extent * extent * 4].chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
        })
    };
    let plain = level0(&build_as("rgba8"));
    let formats =
        [(ImageryFormat::Bc7, BC7_MIN_DB, BC7_MAX_ALPHA_ERROR), (ImageryFormat::Bc1, BC1_MIN_DB, 0)];
    for (format, floor_db, alpha_error) in formats {
        let dataset = build_as(format.short_name());
        let layer = dataset.imagery.as_ref().unwrap();
        assert_eq!(
            (dataset.manifest.imagery.as_ref().unwrap().format.as_str(), layer.block_format),
            (format.name(), Some(format))
        );
        assert_eq!(layer.pack().tile_bytes(), format.tile_bytes(&layer.pyramid, layer.mips));
        let texels = level0(&dataset);
        let (mut squared, mut covered) = (0.0, 0usize);
        for (k, (b, p)) in texels.iter().zip(&plain).enumerate() {
            assert!(b[3].abs_diff(p[3]) <= alpha_error, "{format} texel {k}: alpha {} for {}", b[3], p[3]);
            if p[3] == 255 {
                squared += (0..3).map(|c| (f64::from(b[c]) - f64::from(p[c])).powi(2)).sum::<f64>();
                covered += 3;
            }
        }
        let db = 10.0 * (255.0f64.powi(2) * covered as f64 / squared).log10();
        assert!(db >= floor_db, "{format}: {db:.1} dB over the covered texels");
    }
}

#[test]
fn rainier_voids_are_filled_in_a_local_metric_frame() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("rainier");
    let dem = data.join("rainier/mt_rainier_90m.tif");
    let (dataset, stdout) = build(&tmp.path().join("rainier"), &["--dem", dem.to_str().unwrap()]);
    let manifest = &dataset.manifest;
    assert!(manifest.crs.note.contains("azimuthal equidistant"), "{}", manifest.crs.note);
    // 3 arc-seconds of latitude at 46.5° N.
    let spacing_m = manifest.height.spacing_m;
    assert!((spacing_m - 92.63).abs() < 0.05, "{spacing_m}");
    let (lo, hi) = (manifest.height.min_m, manifest.height.max_m);
    assert!((200.0..400.0).contains(&lo) && (4300.0..=4392.0).contains(&hi), "range {lo} .. {hi}");

    let heights = height_image(&dataset, 0);
    assert!(heights.iter().all(|h| (lo..=hi).contains(h)), "nodata, -32768 or an out-of-range fill survived");
    let mask = mask_image(&dataset);
    let zeros = mask.iter().filter(|&&v| v == 0).count() as u64;
    assert_eq!(manifest.height.filled_samples, zeros);
    for level in 1..dataset.height.pyramid.levels {
        height_image(&dataset, level);
    }

    // The source's ~9,000 void pixels of 63 m × 93 m cover ~6,200 samples of 92.6 m; the rest of
    // the filled samples are the slivers of the local grid beyond the curved edges of the tile.
    let (source, size) = gdal_band(&dem);
    let source_voids = source.iter().filter(|&&v| v == -32768.0).count();
    let expected = source_voids as f64 * (92.6 * 63.2) / (spacing_m * spacing_m);
    let voids = number_before(&stdout, " voids in the source") as f64;
    assert!((voids / expected - 1.0).abs() < 0.15, "{voids} voids, expected about {expected}");

    // Mask and heights where the source's pixels are: 0 inside voids, 1 well inside valid areas,
    // and known values within the relief of their neighbourhood.
    let mut geographic = SpatialRef::from_epsg(4326).unwrap();
    geographic.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let mut frame = SpatialRef::from_wkt(&manifest.crs.definition).unwrap();
    frame.set_axis_mapping_strategy(AxisMappingStrategy::TraditionalGisOrder);
    let to_frame = CoordTransform::new(&geographic, &frame).unwrap();
    let [width, height] = dataset.height.pyramid.size;
    let sample_of = |row: usize, col: usize| {
        let (mut x, mut y) = ([-122.0 + col as f64 / 1200.0], [47.0 - row as f64 / 1200.0]);
        to_frame.transform_coords(&mut x, &mut y, &mut []).unwrap();
        let grid = [(x[0] - manifest.origin_m[0]) / spacing_m, (y[0] - manifest.origin_m[1]) / spacing_m];
        let (gx, gy) = (grid[0].round() as u32, grid[1].round() as u32);
        assert!(gx < width && gy < height);
        (gx, gy, grid)
    };
    let neighbourhood = |row: usize, col: usize, r: usize| {
        let rows = row.saturating_sub(r)..=(row + r).min(size[1] - 1);
        let cols = col.saturating_sub(r)..=(col + r).min(size[0] - 1);
        rows.flat_map(|j| cols.clone().map(move |i| j * size[0] + i)).map(|k| source[k]).collect::<Vec<f64>>()
    };
    let mut checked = [0; 2];
    for row in 3..size[1] - 3 {
        for col in 3..size[0] - 3 {
            let around = neighbourhood(row, col, 2);
            let valid = if around.iter().all(|&v| v == -32768.0) {
                0
            } else if around.iter().all(|&v| v != -32768.0) && (row + col) % 7 == 0 {
                1
            } else {
                continue;
            };
            let (gx, gy, _) = sample_of(row, col);
            assert_eq!(mask[(gy * width + gx) as usize], valid, "row {row}, col {col}");
            checked[usize::from(valid)] += 1;
        }
    }
    assert!(checked[0] > 100 && checked[1] > 100_000, "checked {checked:?} void and valid pixels");
    for (row, col, truth) in RAINIER_KNOWN {
        assert_eq!(
            source[row as usize * size[0] + col as usize],
            truth,
            "the GDAL read of row {row}, col {col}"
        );
        let (_, _, grid) = sample_of(row as usize, col as usize);
        let height = dataset.height_at(grid[0] * spacing_m, grid[1] * spacing_m, 0).unwrap();
        let around = neighbourhood(row as usize, col as usize, 3);
        let (lo, hi) = around.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        assert!(
            (lo..=hi).contains(&height),
            "row {row}, col {col}: {height} m outside {lo} .. {hi} (truth {truth})"
        );
    }
}

#[test]
fn zion_voids_and_nlcd_match_their_sources() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("zion");
    let (dem, nlcd) = (data.join("zion/dem_utm12n_30m.tif"), data.join("zion/nlcd_utm12n_30m.tif"));
    let (dataset, _) = build(
        &tmp.path().join("zion"),
        &["--dem", dem.to_str().unwrap(), "--landcover", nlcd.to_str().unwrap(), "--classes", "nlcd"],
    );
    let manifest = &dataset.manifest;
    let (source, size) = gdal_band(&dem);
    let voids = source.iter().filter(|&&v| v == -32768.0).count() as u64;
    assert!(voids > 0);
    assert_eq!(manifest.height.filled_samples, voids, "on its own grid every void is the source's");
    let (heights, mask) = (height_image(&dataset, 0), mask_image(&dataset));
    let (lo, hi) = (manifest.height.min_m, manifest.height.max_m);
    assert!(lo > 1000.0 && hi < 2900.0, "{lo} .. {hi}");
    for (k, (&height, &valid)) in heights.iter().zip(&mask).enumerate() {
        let (x, y) = ((k % size[0]) as u32, (k / size[0]) as u32);
        let truth = north_first(&source, size, x, y);
        assert_eq!(valid, u8::from(truth != -32768.0), "mask at ({x}, {y})");
        if truth == -32768.0 {
            assert!((lo..=hi).contains(&height), "fill {height} at ({x}, {y})");
        } else {
            assert_eq!(height, truth as f32, "({x}, {y})");
        }
    }
    let layer = &manifest.landcover.as_ref().unwrap().layer;
    assert_eq!((layer.texel_m, layer.pyramid.size_at(1)), (15.0, [1176, 1434]));
    let codes = lcc_codes(&dataset, 1);
    let (source, size) = gdal_band(&nlcd);
    for (k, &code) in codes.iter().enumerate() {
        let (x, y) = ((k % size[0]) as u32, (k / size[0]) as u32);
        assert_eq!(f64::from(code), north_first(&source, size, x, y), "texel ({x}, {y})");
    }
}

#[test]
fn geographic_srtm_alone_builds_without_voids_left() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("srtm");
    let dem = data.join("zion/srtm.tif");
    let (dataset, stdout) =
        build(&tmp.path().join("srtm"), &["--dem", dem.to_str().unwrap(), "--name", "zion"]);
    assert_eq!(dataset.manifest.name, "zion");
    let (lo, hi) = (dataset.manifest.height.min_m, dataset.manifest.height.max_m);
    assert!((1024.0..1100.0).contains(&lo) && (2800.0..=2892.0).contains(&hi), "{lo} .. {hi}\n{stdout}");
    let heights = height_image(&dataset, 0);
    assert!(heights.iter().all(|h| (lo..=hi).contains(h)));
    assert_eq!(number_before(&stdout, " voids in the source"), 0, "{stdout}");

    // An integer DEM's warp is stored on quarter metres by default: each height within an eighth
    // of a metre of the exact build's, in a smaller pack.
    assert_eq!(dataset.manifest.height.step_m, Some(0.25), "{stdout}");
    assert!(heights.iter().all(|h| (h * 4.0).fract() == 0.0));
    let (exact, _) =
        build(&tmp.path().join("srtm-exact"), &["--dem", dem.to_str().unwrap(), "--height-step-m", "0"]);
    assert_eq!(exact.manifest.height.step_m, None);
    let exact_heights = height_image(&exact, 0);
    // `max_or_nan`: a NaN height must fail, where `f32::max` would drop it.
    let worst = heights
        .iter()
        .zip(&exact_heights)
        .map(|(a, b)| f64::from((a - b).abs()))
        .fold(0.0, terramp::reference::worst::max_or_nan);
    assert!(worst <= 0.125, "rounded {worst} m away");
    assert!(exact_heights.iter().any(|h| (h * 4.0).fract() != 0.0), "the exact warp has finer fractions");
    let pack_bytes = |dir: &str| std::fs::metadata(tmp.path().join(dir).join("height.pack")).unwrap().len();
    let (rounded_bytes, exact_bytes) = (pack_bytes("srtm"), pack_bytes("srtm-exact"));
    assert!(rounded_bytes * 3 < exact_bytes * 2, "{rounded_bytes} against {exact_bytes} bytes");
}

#[test]
fn damaged_packs_are_detected() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("damaged");
    let out = tmp.path().join("nc");
    build(&out, &["--dem", data.join("nc/elev_ned_30m.tif").to_str().unwrap()]);
    let pack = out.join("height.pack");
    let last = TileId::new(1, 0, 0);
    let span = {
        let dataset = Dataset::open(&out).unwrap();
        let index = dataset.height.pyramid.tile_index(last).unwrap();
        dataset.height.pack().stored_span(index).unwrap()
    };
    let mut bytes = std::fs::read(&pack).unwrap();
    bytes[(span.start + span.end) as usize / 2] ^= 0x10;
    std::fs::write(&pack, &bytes).unwrap();
    let dataset = Dataset::open(&out).expect("a flipped byte is found when its tile is read, not on open");
    assert!(dataset.height_tile(TileId::new(0, 0, 0)).is_ok());
    assert!(matches!(dataset.height_tile(last), Err(PackError::Corrupt { .. })));
    std::fs::write(&pack, &bytes[..bytes.len() / 2]).unwrap();
    let error = Dataset::open(&out).err().expect("a truncated pack must not open");
    assert!(matches!(error, DatasetError::Pack(PackError::Truncated { .. })), "{error}");
}
