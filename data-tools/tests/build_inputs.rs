//! `terramp-data build` on inputs made here with GDAL (no shared data needed): bad inputs fail
//! clearly, naming the file; voids that straddle tiles are filled identically by every tile.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::{Path, PathBuf};

use gdal::GeoTransform;
use support::{build, height_image, mask_image, run_build, write_geotiff};
use terramp_testkit::TempDir;

const NODATA: f64 = -9999.0;
/// UTM 33N: a projected, metric CRS.
const EPSG: u32 = 32633;

/// Writes a float32 GeoTIFF of `size` heights (row by row from the north) with 25 m pixels.
fn write_dem(path: &Path, size: [usize; 2], heights: Vec<f32>, geo_transform: GeoTransform) -> PathBuf {
    write_geotiff(path, size, heights, geo_transform, EPSG, Some(NODATA))
}

const NORTH_UP: GeoTransform = [500_000.0, 25.0, 0.0, 5_000_000.0, 0.0, -25.0];

/// Asserts that `build` fails, names `file` on stderr and says `what`, and leaves no output.
fn assert_fails(args: &[&str], out: &Path, file: &str, what: &str) {
    let output = run_build(&[args, &["--out", out.to_str().unwrap()]].concat());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{args:?} should fail");
    assert!(stderr.contains(file), "stderr should name {file}: {stderr}");
    assert!(stderr.to_lowercase().contains(what), "stderr should say {what:?}: {stderr}");
    assert!(!out.exists(), "a failed build must leave nothing at {}", out.display());
}

#[test]
fn bad_inputs_fail_naming_the_file() {
    let tmp = TempDir::new("bad-inputs");
    let out = tmp.path().join("out");
    let path = |name: &str| tmp.path().join(name).to_str().unwrap().to_owned();

    assert_fails(&["--dem", &path("missing.tif")], &out, "missing.tif", "no such file");
    std::fs::write(path("empty.tif"), b"").unwrap();
    assert_fails(&["--dem", &path("empty.tif")], &out, "empty.tif", "empty");
    std::fs::write(path("garbage.tif"), b"this is not a TIFF at all, just some text\n".repeat(40)).unwrap();
    assert_fails(&["--dem", &path("garbage.tif")], &out, "garbage.tif", "not a raster");

    let dem = write_dem(Path::new(&path("dem.tif")), [40, 30], vec![100.0; 1200], NORTH_UP);
    let bytes = std::fs::read(&dem).unwrap();
    std::fs::write(path("truncated.tif"), &bytes[..bytes.len() / 2]).unwrap();
    assert_fails(&["--dem", &path("truncated.tif")], &out, "truncated.tif", "truncated.tif");

    let rotated = [500_000.0, 25.0, 3.0, 5_000_000.0, 3.0, -25.0];
    write_dem(Path::new(&path("rotated.tif")), [40, 30], vec![100.0; 1200], rotated);
    assert_fails(&["--dem", &path("rotated.tif")], &out, "rotated.tif", "rotated");

    let dem = dem.to_str().unwrap();
    assert_fails(
        &["--dem", dem, "--imagery", dem, "--bands", "3,2,1"],
        &out,
        "dem.tif",
        "band 3 does not exist",
    );
    assert_fails(
        &["--dem", dem, "--landcover", &path("garbage.tif"), "--classes", "nc"],
        &out,
        "garbage.tif",
        "land cover",
    );
    assert_fails(
        &["--dem", dem, "--landcover", dem, "--classes", "no-such-table"],
        &out,
        "no-such-table",
        "class table",
    );
    for step in ["0.3", "-0.25", "512", "NaN"] {
        let arg = format!("--height-step-m={step}");
        assert_fails(&["--dem", dem, &arg], &out, "--height-step-m", "power of two");
    }
}

/// A sloping DEM of 700 × 600 samples with voids: one sample, a 150-sample square across the
/// tile corner at (256, 256), a strip along the west edge and a thin diagonal scratch.
fn holed_dem() -> (Vec<f32>, [usize; 2]) {
    let size = [700, 600];
    let mut heights = vec![0.0f32; size[0] * size[1]];
    for row in 0..size[1] {
        for col in 0..size[0] {
            let (x, y) = (col as f32, (size[1] - 1 - row) as f32);
            let void = (x == 90.0 && y == 400.0)
                || ((190.0..340.0).contains(&x) && (200.0..350.0).contains(&y))
                || x < 4.0
                || ((500.0..600.0).contains(&x) && (x - y - 100.0).abs() < 1.5);
            heights[row * size[0] + col] =
                if void { NODATA as f32 } else { 500.0 + 0.8 * x - 0.3 * y + 20.0 * (x * 0.05).sin() };
        }
    }
    (heights, size)
}

#[test]
fn voids_across_tiles_are_filled_the_same_by_every_tile() {
    let tmp = TempDir::new("holed");
    let (source, size) = holed_dem();
    let dem = write_dem(&tmp.path().join("holed.tif"), size, source.clone(), NORTH_UP);
    let (dataset, stdout) = build(&tmp.path().join("out"), &["--dem", dem.to_str().unwrap()]);
    let manifest = &dataset.manifest;
    assert_eq!(manifest.origin_m, [500_012.5, 5_000_000.0 - 600.0 * 25.0 + 12.5]);
    let voids = source.iter().filter(|&&h| f64::from(h) == NODATA).count() as u64;
    assert_eq!(manifest.height.filled_samples, voids, "{stdout}");

    // `height_image` checks that every tile's shared edges and borders equal their neighbours'.
    let heights = height_image(&dataset, 0);
    let mask = mask_image(&dataset);
    let (lo, hi) = (manifest.height.min_m, manifest.height.max_m);
    for (k, (&height, &valid)) in heights.iter().zip(&mask).enumerate() {
        let (x, y) = (k % size[0], k / size[0]);
        let truth = source[(size[1] - 1 - y) * size[0] + x];
        assert_eq!(valid, u8::from(f64::from(truth) != NODATA), "mask at ({x}, {y})");
        if valid == 1 {
            assert_eq!(height, truth, "a valid sample changed at ({x}, {y})");
        } else {
            assert!((lo..=hi).contains(&height), "fill {height} outside {lo} .. {hi} at ({x}, {y})");
        }
    }
    for level in 1..dataset.height.pyramid.levels {
        height_image(&dataset, level);
    }
    // The wide void is filled smoothly: no step between neighbours steeper than the terrain's.
    let at = |x: usize, y: usize| heights[y * size[0] + x];
    for y in 200..350 {
        for x in 190..340 {
            let step = (at(x + 1, y) - at(x, y)).abs().max((at(x, y + 1) - at(x, y)).abs());
            assert!(step < 3.0, "a step of {step} m at ({x}, {y})");
        }
    }
}

/// A georeference sidecar (GDAL's PAM `.aux.xml`) beside `image`: UTM 33N, and `NORTH_UP`.
fn write_sidecar(image: &Path) {
    let srs = gdal::spatial_ref::SpatialRef::from_epsg(EPSG).unwrap().to_wkt().unwrap();
    let gt = NORTH_UP.map(|v| v.to_string()).join(", ");
    let xml =
        format!("<PAMDataset>\n  <SRS>{srs}</SRS>\n  <GeoTransform>{gt}</GeoTransform>\n</PAMDataset>\n");
    std::fs::write(format!("{}.aux.xml", image.display()), xml).unwrap();
}

/// Netpbm images (what GDAL's PNM driver reads) of 40 × 30 texels under a GeoTIFF's name: 8-bit
/// grey (P5), 16-bit grey (P5, maxval 65535) and 8-bit RGB (P6), each file's name and bytes.
fn netpbm_images() -> [(&'static str, Vec<u8>); 3] {
    let [w, h] = [40usize, 30];
    let header = |magic: &str, max: u32| format!("{magic}\n{w} {h}\n{max}\n").into_bytes();
    let grey8 = (0..w * h).map(|i| (i * 7 % 256) as u8);
    let grey16 = (0..w * h).flat_map(|i| ((i * 97 % 65536) as u16).to_be_bytes());
    let rgb8 = (0..w * h * 3).map(|i| (i * 5 % 256) as u8);
    [
        ("grey8.tif", [header("P5", 255), grey8.collect()].concat()),
        ("grey16.tif", [header("P5", 65535), grey16.collect()].concat()),
        ("rgb8.tif", [header("P6", 255), rgb8.collect()].concat()),
    ]
}

/// GDAL's PNM driver takes a georeference from a world file only: with a PAM sidecar alone the
/// build fails naming the file, the driver and the sidecar it ignored, and how to georeference it,
/// never GDAL's empty message. The world file it advises makes the same image build.
#[test]
fn netpbm_images_named_tif_with_a_sidecar_fail_naming_the_file_and_the_driver() {
    let tmp = TempDir::new("netpbm");
    let out = tmp.path().join("out");
    for (name, bytes) in netpbm_images() {
        let image = tmp.path().join(name);
        std::fs::write(&image, bytes).unwrap();
        write_sidecar(&image);
        let image = image.to_str().unwrap();
        let output = run_build(&["--dem", image, "--out", out.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{name} built without a geotransform GDAL reads");
        for said in [name, "no geotransform", "PNM driver", &format!("{name}.aux.xml"), ".wld"] {
            assert!(stderr.contains(said), "{name}: stderr should say {said:?}: {stderr}");
        }
        assert!(!stderr.contains("error msg: ''"), "{name}: GDAL's empty message: {stderr}");
        assert!(!out.exists(), "a failed build must leave nothing at {}", out.display());

        // The control: the same image with a world file (centres of the corner texel) builds.
        let [x0, dx, _, y0, _, dy] = NORTH_UP;
        let world = [dx, 0.0, 0.0, dy, x0 + dx / 2.0, y0 + dy / 2.0].map(|v| v.to_string()).join("\n");
        std::fs::write(Path::new(image).with_extension("wld"), world).unwrap();
        let (dataset, _) = build(&out, &["--dem", image]);
        assert_eq!(dataset.manifest.height.pyramid.size, [40, 30], "{name}");
        std::fs::remove_dir_all(&out).unwrap();
    }
}
