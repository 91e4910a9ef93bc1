//! The land cover's LCC quadtree, built from real rasters: every texel of every level (0, 1, 2),
//! decoded through `LccCoding`, gives back the source's code at that level's resolution.
//!
//! Both samples are on their DEM's grid (the build's summary says "copied", and the test checks
//! it), so the builder reads them without warping and the truth is the raster as GDAL reads it,
//! independently of the builder: level 1 is the source texel for texel, level 0 repeats each on its
//! 2 × 2 children, level 2 packs the 4 it covers (the edge texel repeated past an odd size).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::Path;

use support::{build, gdal_band, level_image};
use terramp::dataset::Dataset;
use terramp::dataset::lcc::{LCC_LEVELS, LCC_SOURCE_LEVEL, LccCoding};
use terramp_testkit::{TempDir, shared_data};

/// The source's classes, south row first, with the source's nodata as the table's nodata code.
struct Truth {
    codes: Vec<u8>,
    size: [u32; 2],
    pixel_m: f64,
}

impl Truth {
    fn read(path: &Path, nodata_code: u8) -> Self {
        let source = gdal::Dataset::open(path).unwrap();
        let nodata = source.rasterband(1).unwrap().no_data_value();
        let (values, size) = gdal_band(path);
        let mut codes = Vec::with_capacity(values.len());
        for row in values.chunks_exact(size[0]).rev() {
            for &v in row {
                assert!(Some(v) == nodata || (v.fract() == 0.0 && (0.0..=255.0).contains(&v)), "{v}");
                codes.push(if Some(v) == nodata { nodata_code } else { v as u8 });
            }
        }
        let pixel_m = source.geo_transform().unwrap()[1];
        Self { codes, size: size.map(|n| n as u32), pixel_m }
    }

    /// The code of source texel `q`, the edge repeated beyond the raster.
    fn at(&self, q: [u32; 2]) -> u8 {
        let [x, y] = [0, 1].map(|a| q[a].min(self.size[a] - 1));
        self.codes[(y * self.size[0] + x) as usize]
    }
}

/// Builds `dem` + `landcover`, then checks every texel of every LCC level against GDAL's read.
fn check_lcc(name: &str, dem: &Path, landcover: &Path, classes: &str) -> LccCoding {
    let tmp = TempDir::new(&format!("lcc-{name}"));
    let args =
        ["--dem", dem.to_str().unwrap(), "--landcover", landcover.to_str().unwrap(), "--classes", classes];
    let (dataset, stdout) = build(&tmp.path().join(name), &args);
    let line = stdout.lines().find(|l| l.contains("land cover:")).unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        line.contains("copied"),
        "{name}: the land cover must be on the DEM's grid for this test: {line}"
    );
    let meta = dataset.manifest.landcover.clone().unwrap();
    let coding = meta.coding.clone();
    let truth = Truth::read(landcover, meta.nodata_code);

    // The palette is exactly the source's distinct codes, in the narrowest word.
    let mut distinct = truth.codes.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(coding.palette, distinct, "{name}");
    assert_eq!(coding, LccCoding::for_codes(distinct.iter().copied()).unwrap());
    let expected_line = format!("{} codes in {}-bit LCC words", coding.palette.len(), coding.word_bits);
    assert!(line.contains(&expected_line), "{line}");
    eprintln!(
        "{name}: {} codes {:?} in {}-bit words",
        coding.palette.len(),
        coding.palette,
        coding.word_bits
    );

    let pyramid = dataset.landcover.as_ref().unwrap().pyramid;
    assert_eq!((pyramid.levels, pyramid.size_at(LCC_SOURCE_LEVEL)), (LCC_LEVELS, truth.size));
    assert_eq!(meta.layer.texel_m, 0.5 * truth.pixel_m, "level 0 halves the source's texels");
    assert_eq!(meta.layer.format, format!("lcc r{} palette indices", coding.word_bits));
    for level in 0..LCC_LEVELS {
        // Every stored word, padding included (`level_image` checks it repeats the edge).
        let words = level_image(&pyramid, level, |id| dataset.landcover_words(id).unwrap());
        let width = pyramid.size_at(level)[0];
        let code = |word: u32, q: [u32; 2]| coding.code_of(coding.decode(level, word, q));
        let mut checked = 0u64;
        for (k, &word) in words.iter().enumerate() {
            let texel = [k as u32 % width, k as u32 / width];
            let children: &[[u32; 2]] = match level {
                0 => &[texel.map(|v| v / 2)],
                1 => &[texel],
                _ => &[0, 1, 2, 3].map(|k| [2 * texel[0] + (k & 1), 2 * texel[1] + (k >> 1)]),
            };
            for &q in children {
                assert_eq!(
                    code(word, q),
                    Some(truth.at(q)),
                    "{name}: level {level} texel {texel:?}, source {q:?}"
                );
                checked += 1;
            }
        }
        let source_texels = u64::from(truth.size[0]) * u64::from(truth.size[1]);
        assert!(checked >= source_texels, "{name}: level {level} checked {checked} of {source_texels}");
        // The dataset's own reader agrees, on a sample of source texels.
        for y in (0..truth.size[1]).step_by(23) {
            for x in (0..truth.size[0]).step_by(29) {
                let index = dataset.landcover_index(level, [x, y]).unwrap();
                assert_eq!(coding.code_of(index), Some(truth.at([x, y])), "{name}: level {level} ({x}, {y})");
            }
        }
    }
    check_ranges(&dataset, &coding);
    coding
}

/// Each tile's index range bounds the palette indices it stores.
fn check_ranges(dataset: &Dataset, coding: &LccCoding) {
    let layer = dataset.landcover.as_ref().unwrap();
    for id in layer.pyramid.tiles() {
        let [lo, hi] = layer.tile_range(id).unwrap().expect("land-cover tiles record their index range");
        for word in dataset.landcover_words(id).unwrap() {
            for k in 0..4 {
                let index = coding.decode(id.level, word, [k & 1, k >> 1]) as f32;
                assert!((lo..=hi).contains(&index) && lo >= 1.0, "{id:?}: {index} outside {lo} .. {hi}");
            }
        }
    }
}

#[test]
fn nc_land_use_is_lossless_at_every_level() {
    let Some(data) = shared_data() else { return };
    let nc = data.join("nc");
    let coding = check_lcc("nc", &nc.join("elev_ned_30m.tif"), &nc.join("landuse_r.tif"), "nc");
    // Codes 1..=7 and the nodata code 255: too many for the paper's 2-bit sub-codes.
    assert_eq!((coding.word_bits, coding.palette.as_slice()), (16, &[1, 2, 3, 4, 5, 6, 7, 255][..]));
}

#[test]
fn zion_nlcd_is_lossless_at_every_level() {
    let Some(data) = shared_data() else { return };
    let zion = data.join("zion");
    let coding =
        check_lcc("zion", &zion.join("dem_utm12n_30m.tif"), &zion.join("nlcd_utm12n_30m.tif"), "nlcd");
    // 14 NLCD classes occur, plus nodata: exactly the 15 that 4-bit sub-codes address.
    assert_eq!((coding.word_bits, coding.palette.len()), (16, 15));
}
