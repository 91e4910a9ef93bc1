//! The synthetic dataset generator: determinism, exact height ranges, seamless tiles, valid
//! classes, plausible imagery, odd and tiny sizes, and resolution consistency.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::{Path, PathBuf};
use std::time::Instant;

use terramp::classes::ClassTable;
use terramp::dataset::lcc::LCC_SOURCE_LEVEL;
use terramp::dataset::{Dataset, TileId};
use terramp::synth::{IMAGERY_PACK, LANDCOVER_PACK, SynthError, SynthParams, code, synthesize};

fn temp_out(name: &str) -> PathBuf {
    let root = std::env::temp_dir().join(format!("terramp-synth-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let out = root.join(name);
    let _ = std::fs::remove_dir_all(&out);
    out
}

fn synth(name: &str, params: &SynthParams) -> Dataset {
    let start = Instant::now();
    let dir = synthesize(&temp_out(name), params, false).unwrap();
    eprintln!("{name}: size {} in {:.2?}", params.size, start.elapsed());
    Dataset::open(&dir).unwrap()
}

fn params(size: u32, seed: u64) -> SynthParams {
    SynthParams { size, seed, ..Default::default() }
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap()
}

/// Level-0 height samples, row by row from the south, gathered from the tiles' interiors.
fn level0_heights(dataset: &Dataset) -> Vec<f32> {
    let p = dataset.height.pyramid;
    let (size, extent, border) = (p.size, p.tile_extent() as usize, p.border as usize);
    let mut out = vec![f32::NAN; (size[0] * size[1]) as usize];
    let [nx, ny] = p.tiles_at(0);
    for ty in 0..ny {
        for tx in 0..nx {
            let tile = dataset.height_tile(TileId::new(0, tx, ty)).unwrap();
            for j in 0..=p.tile.min(size[1] - 1 - ty * p.tile) {
                for i in 0..=p.tile.min(size[0] - 1 - tx * p.tile) {
                    let (x, y) = (tx * p.tile + i, ty * p.tile + j);
                    out[(y * size[0] + x) as usize] =
                        tile[(j as usize + border) * extent + i as usize + border];
                }
            }
        }
    }
    assert!(out.iter().all(|h| h.is_finite()));
    out
}

/// The land cover's source classes (LCC level 1, decoded), row by row from the south.
fn source_classes(dataset: &Dataset) -> Vec<u8> {
    let (layer, coding) = (dataset.landcover.as_ref().unwrap(), dataset.lcc_coding().unwrap());
    let p = layer.pyramid;
    let size = p.size_at(LCC_SOURCE_LEVEL);
    let mut out = vec![0u8; (size[0] * size[1]) as usize];
    let [nx, ny] = p.tiles_at(LCC_SOURCE_LEVEL);
    for ty in 0..ny {
        for tx in 0..nx {
            let words = dataset.landcover_words(TileId::new(LCC_SOURCE_LEVEL, tx, ty)).unwrap();
            for j in 0..p.tile.min(size[1] - ty * p.tile) {
                for i in 0..p.tile.min(size[0] - tx * p.tile) {
                    let (x, y) = (tx * p.tile + i, ty * p.tile + j);
                    let index = words[(j * p.tile + i) as usize];
                    out[(y * size[0] + x) as usize] = coding.code_of(index).expect("a palette index");
                }
            }
        }
    }
    out
}

#[test]
fn same_seed_same_bytes_other_seed_other_world() {
    let a = synth("det-a", &params(300, 7));
    let b = synth("det-b", &params(300, 7));
    let c = synth("det-c", &params(300, 8));
    for file in ["height.pack", IMAGERY_PACK, LANDCOVER_PACK, "manifest.toml"] {
        assert!(read(&a.dir.join(file)) == read(&b.dir.join(file)), "{file} differs between identical runs");
    }
    assert!(read(&a.dir.join("height.pack")) != read(&c.dir.join("height.pack")));
    assert!(read(&a.dir.join(IMAGERY_PACK)) != read(&c.dir.join(IMAGERY_PACK)));
}

#[test]
fn heights_are_the_world_function_with_an_exact_range_and_seamless_tiles() {
    let p = params(600, 1);
    let dataset = synth("heights", &p);
    let terrain = p.terrain();
    let heights = level0_heights(&dataset);
    for (k, &h) in heights.iter().enumerate() {
        let (i, j) = (k as u32 % p.size, k as u32 / p.size);
        let expected = terrain.height_m(f64::from(i) * p.spacing_m, f64::from(j) * p.spacing_m) as f32;
        assert_eq!(h, expected, "sample ({i}, {j})");
    }
    let min = heights.iter().copied().fold(f32::INFINITY, f32::min);
    let max = heights.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let layer = &dataset.manifest.height;
    assert_eq!((layer.min_m, layer.max_m), (min, max));
    assert!(max - min > 100.0, "relief {min}..{max} is too flat");
    assert!(min >= p.water_level_m as f32, "the stored surface never dips under the water");

    // Every stored sample, borders included, is the sample of its grid position: shared edges
    // and borders equal their neighbours', at every level.
    let pyramid = dataset.height.pyramid;
    let extent = pyramid.tile_extent() as i64;
    for id in pyramid.tiles() {
        let tile = dataset.height_tile(id).unwrap();
        let [x0, y0] = pyramid.tile_origin(id);
        let size = pyramid.size_at(id.level).map(i64::from);
        for j in 0..extent {
            for i in 0..extent {
                let (x, y) = ((x0 + i).clamp(0, size[0] - 1), (y0 + j).clamp(0, size[1] - 1));
                let step = 1 << id.level;
                let fine = [(x * step).min(i64::from(p.size) - 1), (y * step).min(i64::from(p.size) - 1)];
                let expected = heights[(fine[1] * i64::from(p.size) + fine[0]) as usize];
                assert_eq!(tile[(j * extent + i) as usize], expected, "{id:?} ({i}, {j})");
            }
        }
    }
}

#[test]
fn classes_are_in_the_table_and_water_lies_below_the_surface() {
    let p = params(300, 1);
    let dataset = synth("classes", &p);
    let table = ClassTable::load("nc").unwrap();
    let manifest = dataset.manifest.landcover.as_ref().unwrap();
    assert_eq!((manifest.scheme.as_str(), manifest.nodata_code), ("nc", 255));
    assert_eq!(manifest.classes, table.names());
    let coding = dataset.lcc_coding().unwrap();
    assert!(
        coding.palette.iter().all(|&c| table.contains(c)),
        "{coding:?} holds a code outside the nc table"
    );
    assert_eq!(coding.word_bits, if coding.palette.len() <= 3 { 8 } else { 16 });
    let layer = dataset.landcover.as_ref().unwrap();
    for id in layer.pyramid.tiles() {
        let words = dataset.landcover_words(id).unwrap();
        let sub_codes = if id.level == 2 { 4 } else { 1 };
        let indices = words
            .iter()
            .flat_map(|&w| (0..sub_codes).map(move |k| coding.decode(id.level, w, [k & 1, k >> 1])));
        let indices: Vec<u32> = indices.collect();
        assert!(indices.iter().all(|&i| coding.code_of(i).is_some()), "{id:?} holds a bare or unknown index");
    }
    let classes = source_classes(&dataset);
    let terrain = p.terrain();
    // Level 0's texels are half the source's.
    let texel_m = 2.0 * manifest.layer.texel_m;
    let size = layer.pyramid.size_at(LCC_SOURCE_LEVEL);
    let mut seen = [0usize; 8];
    for (k, &class) in classes.iter().enumerate() {
        let (i, j) = (k as u32 % size[0], k as u32 / size[0]);
        let centre = |i: u32| (f64::from(i) + 0.5) * texel_m - 0.5 * p.spacing_m;
        let relief_m = terrain.relief(centre(i), centre(j)).v;
        assert_eq!(
            class == code::WATER,
            relief_m < 0.0,
            "texel ({i}, {j}): class {class}, relief {relief_m} m"
        );
        seen[class as usize] += 1;
    }
    eprintln!("class histogram {seen:?}");
    assert!(seen[code::WATER as usize] > 0, "the test area should hold some water");
    assert!(seen.iter().filter(|&&n| n > 0).count() >= 5, "{seen:?}: too few classes");
}

#[test]
fn imagery_is_opaque_and_varied() {
    let dataset = synth("imagery", &params(300, 3));
    let imagery = dataset.imagery.as_ref().unwrap();
    let manifest = dataset.manifest.imagery.as_ref().unwrap();
    assert_eq!(manifest.texel_m, 2.5);
    assert_eq!(imagery.pyramid.size, [1200, 1200]);
    for id in imagery.pyramid.tiles() {
        let tile = imagery.tile_bytes(id).unwrap();
        assert!(!tile.is_empty());
        assert!(tile.chunks_exact(4).all(|t| t[3] == 255), "{id:?}: not opaque");
        let texels = (tile.len() / 4) as f64;
        let green = tile.chunks_exact(4).map(|t| f64::from(t[1]));
        let mean = green.clone().sum::<f64>() / texels;
        let sigma = (green.map(|g| (g - mean).powi(2)).sum::<f64>() / texels).sqrt();
        assert!(sigma > 5.0, "{id:?}: nearly uniform (σ = {sigma})");
        // Aerial colours: neither black nor blown out on average.
        assert!((25.0..230.0).contains(&mean), "{id:?}: mean green {mean}");
    }
}

#[test]
fn odd_and_tiny_sizes_work() {
    for size in [1, 2, 3, 257, 258] {
        let dataset = synth(&format!("size-{size}"), &params(size, 5));
        assert_eq!(dataset.height.pyramid.size, [size, size]);
        assert_eq!(dataset.imagery.as_ref().unwrap().pyramid.size, [4 * size, 4 * size]);
        let landcover = dataset.landcover.as_ref().unwrap().pyramid;
        assert_eq!((landcover.size_at(LCC_SOURCE_LEVEL), landcover.size), ([2 * size; 2], [4 * size; 2]));
        let heights = level0_heights(&dataset);
        // Finite first: `f32::min` and `f32::max` below would drop a NaN.
        assert!(heights.iter().all(|h| h.is_finite()), "size {size}: a height is not finite");
        let layer = &dataset.manifest.height;
        assert_eq!(layer.min_m, heights.iter().copied().fold(f32::INFINITY, f32::min));
        assert_eq!(layer.max_m, heights.iter().copied().fold(f32::NEG_INFINITY, f32::max));
    }
}

#[test]
fn finer_spacing_samples_the_same_world() {
    let coarse = SynthParams { size: 150, spacing_m: 10.0, ..params(0, 11) };
    let fine = SynthParams { size: 299, spacing_m: 5.0, ..params(0, 11) };
    let (a, b) = (synth("spacing-10", &coarse), synth("spacing-5", &fine));
    for j in 0..150 {
        for i in 0..150 {
            assert_eq!(
                a.height_sample(0, i, j).unwrap(),
                b.height_sample(0, 2 * i, 2 * j).unwrap(),
                "({i}, {j})"
            );
        }
    }
}

#[test]
fn origin_moves_the_frame_not_the_world() {
    let shifted = SynthParams { origin_m: [630_015.0, 215_015.0], ..params(64, 2) };
    let a = synth("origin-0", &params(64, 2));
    let b = synth("origin-utm", &shifted);
    assert_eq!(b.manifest.origin_m, shifted.origin_m);
    assert_eq!(b.manifest.corner_m(), [630_010.0, 215_010.0]);
    for file in ["height.pack", IMAGERY_PACK, LANDCOVER_PACK] {
        assert!(read(&a.dir.join(file)) == read(&b.dir.join(file)), "{file}");
    }
}

#[test]
fn bad_parameters_are_refused_before_writing() {
    let out = temp_out("refused");
    assert!(matches!(synthesize(&out, &params(0, 1), false), Err(SynthError::Size(0))));
    let spacing = SynthParams { spacing_m: -1.0, ..params(8, 1) };
    assert!(matches!(synthesize(&out, &spacing, false), Err(SynthError::Spacing(_))));
    let origin = SynthParams { origin_m: [f64::NAN, 0.0], ..params(8, 1) };
    assert!(matches!(synthesize(&out, &origin, false), Err(SynthError::NotFinite(..))));
    assert!(!out.exists());
}
