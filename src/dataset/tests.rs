use std::path::PathBuf;

use indicatif::ProgressBar;

use super::*;

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
    bytemuck::cast_slice(pack.tile(index).unwrap()).to_vec()
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

#[test]
fn classes_are_lossless_at_level_zero_and_never_invented() {
    let spec = LayerSpec {
        name: "landcover",
        pyramid: Pyramid::new([50, 30], 16, 0, Sampling::Cell),
        mips: 1,
        reduce: Reduce::Mode,
    };
    let path = temp_dir("classes").join("landcover.pack");
    let class = |x: u32, y: u32| [11u8, 41, 42, 95][((x / 3 + y / 5) % 4) as usize];
    write_layer(&path, &spec, source_of(class), &ProgressBar::hidden()).unwrap();
    let pack = Pack::open(&path).unwrap();
    for id in spec.pyramid.tiles() {
        let tile = pack.tile(spec.pyramid.tile_index(id).unwrap()).unwrap();
        if id.level == 0 {
            for (k, &c) in tile.iter().enumerate() {
                let (x, y) = (id.x * 16 + k as u32 % 16, id.y * 16 + k as u32 / 16);
                assert_eq!(c, class(x.min(49), y.min(29)));
            }
        } else {
            assert!(tile.iter().all(|c| [11, 41, 42, 95].contains(c)));
        }
    }
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
            filled_samples: 0,
            valid_mask_pack: None,
        },
        imagery: None,
        landcover: None,
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
