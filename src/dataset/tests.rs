use std::path::PathBuf;

use indicatif::ProgressBar;

use super::*;
use crate::dataset::lcc::{self, LccCoding};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("terramp-dataset-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A height field whose every sample is distinct, so misplaced samples cannot hide.
fn height_of(x: u32, y: u32) -> f32 {
    x as f32 * 0.5 + y as f32 * 1000.0
}

fn source_of<T: Copy>(f: impl Fn(u32, u32) -> T) -> impl Fn(Window) -> Result<Vec<T>, String> {
    move |w: Window| {
        Ok((w.y0..w.y0 + w.height)
            .flat_map(|y| (w.x0..w.x0 + w.width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect())
    }
}

fn write_heights(name: &str, size: [u32; 2]) -> (PathBuf, LayerSpec) {
    let spec = LayerSpec {
        name: "height",
        pyramid: Pyramid::new(size, 8, 1, Sampling::Vertex),
        mips: 1,
        reduce: Reduce::Decimate,
    };
    let path = temp_dir(name).join("height.pack");
    write_layer(&path, &spec, source_of(height_of), &ProgressBar::hidden()).unwrap();
    (path, spec)
}

fn tile_f32(pack: &Pack, spec: &LayerSpec, id: TileId) -> Vec<f32> {
    let index = spec.pyramid.tile_index(id).unwrap();
    bytemuck::pod_collect_to_vec(&pack.tile(index).unwrap())
}

#[test]
fn heights_reproduce_the_source_and_match_across_borders() {
    let (path, spec) = write_heights("heights", [37, 21]);
    let pack = Pack::open(&path).unwrap();
    let p = spec.pyramid;
    let extent = p.tile_extent() as i64;
    for id in p.tiles() {
        let tile = tile_f32(&pack, &spec, id);
        let [x0, y0] = p.tile_origin(id);
        let size = p.size_at(id.level);
        let step = 1u32 << id.level;
        for j in 0..extent {
            for i in 0..extent {
                // Beyond the edge the edge sample repeats; coarse samples are the fine ones.
                let gx = (x0 + i).clamp(0, i64::from(size[0]) - 1) as u32;
                let gy = (y0 + j).clamp(0, i64::from(size[1]) - 1) as u32;
                let fine = [(gx * step).min(36), (gy * step).min(20)];
                assert_eq!(tile[(j * extent + i) as usize], height_of(fine[0], fine[1]), "{id:?} ({i},{j})");
            }
        }
    }
}

#[test]
fn imagery_mips_and_levels_are_consistent_box_filters() {
    let spec = LayerSpec {
        name: "imagery",
        pyramid: Pyramid::new([40, 24], 16, 4, Sampling::Cell),
        mips: 3,
        reduce: Reduce::Mean,
    };
    let path = temp_dir("imagery").join("imagery.pack");
    let colour = |x: u32, y: u32| [(x * 6) as u8, (y * 10) as u8, ((x + y) % 7 * 30) as u8, 255];
    write_layer(&path, &spec, source_of(colour), &ProgressBar::hidden()).unwrap();
    let pack = Pack::open(&path).unwrap();
    let p = spec.pyramid;
    let extent = p.tile_extent() as usize;
    // Mip 1 of a level-0 tile equals the interior of the level-1 tile that covers it.
    let fine = pack.tile(p.tile_index(TileId::new(0, 0, 0)).unwrap()).unwrap();
    let coarse = pack.tile(p.tile_index(TileId::new(1, 0, 0)).unwrap()).unwrap();
    let mip1 = &fine[extent * extent * 4..];
    let half = extent / 2;
    let b = p.border as usize;
    for j in b / 2..half - b / 2 {
        for i in b / 2..half - b / 2 {
            let in_mip = &mip1[(j * half + i) * 4..][..4];
            let in_level = &coarse[((j + b / 2) * extent + i + b / 2) * 4..][..4];
            assert_eq!(in_mip, in_level, "texel ({i},{j})");
        }
    }
}

/// Writes a staged dataset of 37 × 21 heights and an LCC land cover of `size` source texels.
fn lcc_dataset(name: &str, size: [u32; 2], class: impl Fn(u32, u32) -> u8 + Sync) -> Dataset {
    let out = temp_dir(name).join("ds");
    let staging = Staging::begin(&out).unwrap();
    let spec =
        LayerSpec { pyramid: Pyramid::new([37, 21], 8, 1, Sampling::Vertex), ..LayerSpec::heights([37, 21]) };
    write_layer(&staging.path("height.pack"), &spec, source_of(height_of), &ProgressBar::hidden()).unwrap();
    let counts = lcc::scan_codes(size, &source_of(&class), &ProgressBar::hidden()).unwrap();
    let coding = LccCoding::for_codes(counts.present()).unwrap();
    let path = staging.path("landcover.pack");
    let pyramid =
        lcc::write_lcc_layer(&path, size, &coding, source_of(&class), &ProgressBar::hidden()).unwrap();
    let layer = CellLayer {
        pack: "landcover.pack".into(),
        texel_m: 5.0,
        pyramid,
        mips: 1,
        format: coding.format_name(),
        source: "test".into(),
    };
    let landcover =
        LandcoverLayer { layer, coding, scheme: "test".into(), classes: Vec::new(), nodata_code: 255 };
    staging.commit(&Manifest { landcover: Some(landcover), ..manifest_for(&spec) }).unwrap();
    Dataset::open(&out).unwrap()
}

#[test]
fn lcc_levels_decode_to_the_source_codes_everywhere() {
    // Odd sizes: level 2's last column and row pack replicated edge texels; the layer spans
    // several tiles at levels 0 and 1, one at level 2.
    let size = [701, 263];
    let class = |x: u32, y: u32| [11u8, 41, 42, 95, 255][((x / 3 + y / 5 + x * y % 7) % 5) as usize];
    let dataset = lcc_dataset("lcc", size, class);
    let coding = dataset.lcc_coding().unwrap().clone();
    assert_eq!((coding.word_bits, coding.palette.clone()), (16, vec![11, 41, 42, 95, 255]));
    let layer = dataset.landcover.as_ref().unwrap();
    let p = layer.pyramid;
    assert_eq!(
        (p.levels, p.size_at(1), p.tiles_at(0), p.tiles_at(2)),
        (lcc::LCC_LEVELS, size, [3, 2], [1, 1])
    );
    for level in 0..lcc::LCC_LEVELS {
        // Every stored word, padding included, through the tile reader.
        let tile = p.tile as usize;
        for id in (0..p.tiles_at(level)[1])
            .flat_map(|y| (0..p.tiles_at(level)[0]).map(move |x| TileId::new(level, x, y)))
        {
            let words = dataset.landcover_words(id).unwrap();
            assert_eq!(words.len(), tile * tile);
            let range = layer.tile_range(id).unwrap().expect("land-cover tiles have an index range");
            for (k, &word) in words.iter().enumerate() {
                let texel = [id.x * p.tile + (k % tile) as u32, id.y * p.tile + (k / tile) as u32];
                let texel = [0, 1].map(|a| texel[a].min(p.size_at(level)[a] - 1));
                let expected = match level {
                    0 => coding.index_of(class(texel[0] / 2, texel[1] / 2)),
                    1 => coding.index_of(class(texel[0], texel[1])),
                    _ => coding.pack([0, 1, 2, 3].map(|k| {
                        let q = [
                            (2 * texel[0] + (k & 1)).min(size[0] - 1),
                            (2 * texel[1] + (k >> 1)).min(size[1] - 1),
                        ];
                        coding.index_of(class(q[0], q[1]))
                    })),
                };
                assert_eq!(word, expected, "{id:?} texel {texel:?}");
                for sub in 0..if level == 2 { 4 } else { 1 } {
                    let index = coding.decode(level, word, [sub & 1, sub >> 1]) as f32;
                    assert!(range[0] <= index && index <= range[1], "{id:?}: {index} outside {range:?}");
                }
            }
        }
        // Every source texel, read back from each level.
        for y in 0..size[1] {
            for x in 0..size[0] {
                let index = dataset.landcover_index(level, [x, y]).unwrap();
                assert_eq!(coding.code_of(index), Some(class(x, y)), "level {level}, texel ({x}, {y})");
            }
        }
    }
    assert_eq!(
        dataset.landcover_index(2, [5000, 5000]).unwrap(),
        dataset.landcover_index(1, [700, 262]).unwrap()
    );
}

#[test]
fn an_lcc_layer_of_one_texel_still_has_three_levels() {
    let dataset = lcc_dataset("lcc-one", [1, 1], |_, _| 7);
    let coding = dataset.lcc_coding().unwrap();
    assert_eq!((coding.word_bits, coding.palette.as_slice()), (8, &[7u8][..]));
    for level in 0..3 {
        assert_eq!(dataset.landcover_index(level, [0, 0]).unwrap(), 1);
        let words = dataset.landcover_words(TileId::new(level, 0, 0)).unwrap();
        let expected = if level == 2 { 0b01_01_01_01 } else { 1 };
        assert!(words.iter().all(|&w| w == expected), "level {level}");
    }
}

#[test]
fn codes_missing_from_the_palette_are_refused() {
    let path = temp_dir("lcc-missing").join("landcover.pack");
    let coding = LccCoding::for_codes([1, 2]).unwrap();
    let class = |x: u32, _| if x == 5 { 3 } else { 1 };
    let err =
        lcc::write_lcc_layer(&path, [9, 9], &coding, source_of(class), &ProgressBar::hidden()).unwrap_err();
    assert!(matches!(err, LayerError::Lcc(lcc::LccError::NotInPalette { code: 3 })), "{err}");
}

#[test]
fn source_errors_name_the_layer_and_window() {
    let spec = LayerSpec {
        name: "height",
        pyramid: Pyramid::new([9, 9], 8, 1, Sampling::Vertex),
        mips: 1,
        reduce: Reduce::Decimate,
    };
    let path = temp_dir("source-error").join("height.pack");
    let failing = |_: Window| -> Result<Vec<f32>, String> { Err("block 3 is corrupt".into()) };
    let err = write_layer(&path, &spec, failing, &ProgressBar::hidden()).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("height") && text.contains("block 3 is corrupt"), "{text}");
}

fn manifest_for(spec: &LayerSpec) -> Manifest {
    Manifest {
        format_version: FORMAT_VERSION,
        name: "test".into(),
        crs: Crs { definition: "EPSG:32119".into(), note: "test".into() },
        origin_m: [630_015.0, 215_015.0],
        height: HeightLayer {
            pack: "height.pack".into(),
            spacing_m: 30.0,
            pyramid: spec.pyramid,
            min_m: 0.0,
            max_m: 20_000.0,
            step_m: None,
            filled_samples: 0,
            valid_mask_pack: None,
        },
        imagery: None,
        landcover: None,
        vegetation: None,
        earth: None,
    }
}

#[test]
fn staged_dataset_appears_whole_and_reads_back() {
    let root = temp_dir("staging");
    let out = root.join("ds");
    let spec = LayerSpec {
        name: "height",
        pyramid: Pyramid::new([37, 21], 8, 1, Sampling::Vertex),
        mips: 1,
        reduce: Reduce::Decimate,
    };
    let staging = Staging::begin(&out).unwrap();
    write_layer(&staging.path("height.pack"), &spec, source_of(height_of), &ProgressBar::hidden()).unwrap();
    assert!(!out.exists(), "nothing is visible before commit");
    staging.commit(&manifest_for(&spec)).unwrap();
    let dataset = Dataset::open(&out).unwrap();
    assert_eq!(dataset.height_sample(0, 36, 20).unwrap(), f64::from(height_of(36, 20)));
    assert_eq!(dataset.height_sample(1, 3, 2).unwrap(), f64::from(height_of(6, 4)));
    // Halfway between samples (1, 2) and (2, 2), a quarter of the way to row 3.
    let h = dataset.height_at(45.0, 67.5, 0).unwrap();
    assert!((h - (0.75 + 2250.0)).abs() < 1e-9, "{h}");

    // A failed rebuild leaves the previous dataset untouched and no staging folder behind.
    let staging = Staging::begin(&out).unwrap();
    std::fs::write(staging.path("height.pack"), b"half").unwrap();
    drop(staging);
    assert!(Dataset::open(&out).is_ok());
    let leftovers =
        std::fs::read_dir(&root).unwrap().filter(|e| e.as_ref().unwrap().file_name() != "ds").count();
    assert_eq!(leftovers, 0);
}

#[test]
fn user_folders_are_never_replaced() {
    let root = temp_dir("not-a-dataset");
    std::fs::write(root.join("thesis.tex"), b"precious").unwrap();
    assert!(matches!(Staging::begin(&root), Err(DatasetError::NotADataset { .. })));
}

#[test]
fn height_ranges_bound_every_fine_sample_beneath() {
    // A spike on an odd sample: decimation drops it from level 1, the range must not.
    let spike = |x: u32, y: u32| if (x, y) == (13, 7) { 50_000.0 } else { height_of(x, y) };
    let spec =
        LayerSpec { pyramid: Pyramid::new([37, 21], 8, 1, Sampling::Vertex), ..LayerSpec::heights([37, 21]) };
    let path = temp_dir("ranges").join("height.pack");
    write_layer(&path, &spec, source_of(spike), &ProgressBar::hidden()).unwrap();
    let pack = Pack::open(&path).unwrap();
    for id in spec.pyramid.tiles() {
        let index = spec.pyramid.tile_index(id).unwrap();
        let [lo, hi] = pack.tile_range(index).unwrap().expect("heights have ranges");
        assert!(tile_f32(&pack, &spec, id).iter().all(|&h| lo <= h && h <= hi), "{id:?}");
        let span = 8 << id.level;
        if id.level > 0 && (id.x, id.y) == (13 / span, 7 / span) {
            assert_eq!(hi, 50_000.0, "{id:?} lies over the spike");
        }
    }
}

#[test]
fn datasets_of_another_format_version_say_so() {
    let (path, spec) = write_heights("old-version", [37, 21]);
    let dir = path.parent().unwrap();
    let mut text = toml::to_string_pretty(&manifest_for(&spec)).unwrap();
    // A version-1 land cover had no `coding`: the version must be what is reported, not that.
    text = text.replace(&format!("format_version = {FORMAT_VERSION}"), "format_version = 1");
    text.push_str("\n[landcover]\npack = \"landcover.pack\"\nformat = \"r8 class codes\"\n");
    std::fs::write(dir.join(MANIFEST_FILE), text).unwrap();
    assert!(matches!(Dataset::open(dir), Err(DatasetError::Version { found: 1, .. })));
}

#[test]
fn a_bad_lcc_coding_is_refused_naming_the_manifest() {
    let dataset = lcc_dataset("lcc-bad", [4, 4], |x, _| x as u8);
    let path = dataset.dir.join(MANIFEST_FILE);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        text.replace("word_bits = 16", "word_bits = 12").replace("word_bits = 8", "word_bits = 12"),
    )
    .unwrap();
    let err = Dataset::open(&dataset.dir).err().expect("a 12-bit coding must not open");
    assert!(matches!(&err, DatasetError::Manifest { path: p, .. } if *p == path), "{err}");
    assert!(err.to_string().contains("12 bits"), "{err}");
}

#[test]
fn stored_tiles_have_the_extents_the_shaders_read() {
    use crate::gpu::layout::{HEIGHT_TILE_EXTENT, IMAGERY_TILE_EXTENT};
    for size in [[1, 1], [257, 257], [1000, 3]] {
        assert_eq!(LayerSpec::heights(size).pyramid.tile_extent(), HEIGHT_TILE_EXTENT);
        assert_eq!(LayerSpec::imagery(size).pyramid.tile_extent(), IMAGERY_TILE_EXTENT);
    }
}

/// Writes 40 × 24 texels of RGBA8 imagery as `imagery.pack` in `dir`; its manifest layer.
fn write_imagery(dir: &std::path::Path) -> CellLayer {
    let imagery = LayerSpec::imagery([40, 24]);
    let colour = |x: u32, y: u32| [x as u8, y as u8, 0, 255];
    write_layer(&dir.join("imagery.pack"), &imagery, source_of(colour), &ProgressBar::hidden()).unwrap();
    CellLayer {
        pack: "imagery.pack".into(),
        texel_m: 28.5,
        pyramid: imagery.pyramid,
        mips: imagery.mips,
        format: ImageryFormat::Rgba8.name().into(),
        source: "test".into(),
    }
}

#[test]
fn an_imagery_format_unknown_or_unlike_its_pack_is_refused() {
    let (path, spec) = write_heights("imagery-format", [37, 21]);
    let dir = path.parent().unwrap();
    let imagery = write_imagery(dir);
    let with_format = |format: &str| {
        let layer = CellLayer { format: format.into(), ..imagery.clone() };
        let text = toml::to_string_pretty(&Manifest { imagery: Some(layer), ..manifest_for(&spec) }).unwrap();
        std::fs::write(dir.join(MANIFEST_FILE), text).unwrap();
        Dataset::open(dir)
    };
    assert!(with_format("rgba8 srgb").is_ok());
    let err = with_format("bc3 srgb").err().expect("an unknown format");
    assert!(
        matches!(err, DatasetError::Manifest { .. }) && err.to_string().contains("\"bc3 srgb\""),
        "{err}"
    );
    // An RGBA8 pack under a BC7 manifest: its tiles are 4 times the size the format says.
    let err = with_format("bc7 srgb").err().expect("a pack of another format");
    assert!(matches!(err, DatasetError::PackShape { .. }), "{err}");
}

/// A manifest's pyramid and mips feed shifts, products and divisions: 40 levels shift by 32 bits
/// and more, a tile of 0 divides by zero, a border of 2^31 doubles past u32, 40 imagery mips
/// shift the tile's side away. Each panicked (the division in every build, the rest with overflow
/// in a debug one; found by the overflow audit, issue 42); each is refused naming the manifest and
/// the field now, as is a spacing of 0 m, which made every position NaN.
#[test]
fn pyramids_whose_arithmetic_would_overflow_are_refused_naming_the_field() {
    let (path, spec) = write_heights("overflow", [37, 21]);
    let dir = path.parent().unwrap();
    let good = Manifest { imagery: Some(write_imagery(dir)), ..manifest_for(&spec) };
    let open_with = |edit: &dyn Fn(&mut Manifest)| {
        let mut manifest = good.clone();
        edit(&mut manifest);
        std::fs::write(dir.join(MANIFEST_FILE), toml::to_string_pretty(&manifest).unwrap()).unwrap();
        Dataset::open(dir).map(|_| ())
    };
    assert!(open_with(&|_| ()).is_ok());
    type Edit<'a> = &'a dyn Fn(&mut Manifest);
    let cases: [(&str, Edit); 5] = [
        ("height.pyramid.levels", &|m| m.height.pyramid.levels = 40),
        ("height.pyramid.tile", &|m| m.height.pyramid.tile = 0),
        ("height.pyramid.border", &|m| m.height.pyramid.border = 1 << 31),
        ("imagery.mips", &|m| m.imagery.iter_mut().for_each(|l| l.mips = 40)),
        ("height.spacing_m", &|m| m.height.spacing_m = 0.0),
    ];
    for (field, edit) in cases {
        let err = open_with(edit).expect_err(field);
        assert!(
            matches!(&err, DatasetError::Manifest { path, .. } if path.ends_with(MANIFEST_FILE)),
            "{err}"
        );
        assert!(err.to_string().contains(field), "{field}: {err}");
    }
}

/// A pack's header sizes feed sums and allocations: a data size of 2^64 − 1 bytes or a tile count
/// just under 2^59 pass past u64 when the file's length is summed, a tile size of 2^64 − 2 bytes
/// overflows with Grid32's 3 leading bytes, and one of 2^40 bytes was allocated up front to
/// decompress into. The sums panicked with overflow in a debug build (found by the overflow audit,
/// issue 42), the allocation aborted in any (found by `fuzz/`'s `pack` once it made the checksums
/// match); each is an error naming the pack now: truncated at open, or that tile corrupt.
#[test]
fn pack_headers_whose_arithmetic_would_overflow_are_refused_not_a_panic() {
    let dir = temp_dir("pack-overflow");
    let pack_with = |name: &str, codec: Codec, field: std::ops::Range<usize>, value: u64| {
        let path = dir.join(name);
        let writer = pack::PackWriter::create(&path, 16, 1, codec).unwrap();
        writer.write_tile(0, &[7; 16], None).unwrap();
        writer.finish().unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[field].copy_from_slice(&value.to_le_bytes());
        let crc = crc32fast::hash(&bytes[0..60]);
        bytes[60..64].copy_from_slice(&crc.to_le_bytes());
        std::fs::write(&path, bytes).unwrap();
        Pack::open(&path)
    };
    let (tile_bytes, tile_count, data_bytes) = (16..24, 24..32, 40..48);
    let raw = Codec::Raw;
    let err = pack_with("data.pack", raw, data_bytes, u64::MAX).err().expect("a data size past u64");
    assert!(matches!(err, PackError::Truncated { .. }), "{err}");
    let err = pack_with("count.pack", raw, tile_count, u64::MAX / 32).err().expect("an index past u64");
    assert!(matches!(err, PackError::Truncated { .. }), "{err}");
    for (name, predictor, size) in
        [("grid.pack", Predictor::Grid32, u64::MAX - 1), ("big.pack", Predictor::None, 1 << 40)]
    {
        let pack = pack_with(name, Codec::Zstd(predictor), tile_bytes.clone(), size).unwrap();
        assert!(matches!(pack.tile(0), Err(PackError::Corrupt { index: 0, .. })), "{name}");
    }
    // The pack as written reads back.
    let good = pack_with("good.pack", raw, 0..8, u64::from_le_bytes(*b"TRMPPACK")).unwrap();
    assert_eq!(&*good.tile(0).unwrap(), &[7; 16]);
}
