use std::collections::HashSet;
use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use super::*;
use crate::dataset::lcc::{LccCoding, write_lcc_layer};
use crate::dataset::{LayerSpec, Texel, Window, write_layer};

/// A source whose texels vary everywhere (so that a texel taken from the wrong place shows).
fn source<T: Send>(f: impl Fn(u32, u32) -> T + Sync) -> impl Fn(Window) -> Result<Vec<T>, String> + Sync {
    move |w: Window| {
        Ok((0..w.height)
            .flat_map(|j| (0..w.width).map(|i| f(w.x0 + i, w.y0 + j)).collect::<Vec<_>>())
            .collect())
    }
}

fn hash(x: u32, y: u32) -> u32 {
    let mut h = x.wrapping_mul(0x9E37_79B1) ^ y.wrapping_mul(0x85EB_CA77);
    h ^= h >> 15;
    h.wrapping_mul(0xC2B2_AE3D) ^ (h >> 13)
}

fn height(x: u32, y: u32) -> f32 {
    (x as f32 * 0.37).sin() * 40.0 + y as f32 * 0.21 + (hash(x, y) % 97) as f32 * 0.125 - 30.0
}

fn rgba(x: u32, y: u32) -> [u8; 4] {
    let h = hash(x, y);
    [(x % 251) as u8, (y % 241) as u8, h as u8, (h >> 8) as u8 | 0x80]
}

/// Writes `spec`'s layer whole and as `partitions` parts merged; returns both packs' bytes.
fn whole_and_merged<T: Texel, S>(
    dir: &Path,
    spec: &LayerSpec,
    partitions: u32,
    source: &S,
) -> (Vec<u8>, Vec<u8>)
where
    S: Fn(Window) -> Result<Vec<T>, String> + Sync,
{
    let bar = ProgressBar::hidden();
    let whole = dir.join("whole.pack");
    write_layer(&whole, spec, source, &bar).unwrap();
    let split = Split::new(spec.pyramid, partitions, size_of::<T>() as u64, 0);
    let parts = part_paths(dir, partitions);
    for (part, path) in parts.iter().enumerate() {
        write_layer_part(path, spec, &split, part as u32, source, &bar).unwrap();
    }
    let merged = dir.join("merged.pack");
    merge_layer::<T>(&merged, spec, &split, &parts, &bar).unwrap();
    (std::fs::read(whole).unwrap(), std::fs::read(merged).unwrap())
}

/// A fresh scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("terramp-partition-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn part_paths(dir: &Path, partitions: u32) -> Vec<PathBuf> {
    (0..partitions).map(|i| dir.join(format!("part-{i}.pack"))).collect()
}

#[test]
fn the_roots_are_dealt_once_and_every_tile_is_in_one_part() {
    let pyramid = LayerSpec::heights([1100, 900]).pyramid;
    for partitions in [1, 2, 3, 7, 40] {
        let split = Split::new(pyramid, partitions, 4, 0);
        let mut seen = HashSet::new();
        for part in 0..partitions {
            for id in split.tiles(part) {
                assert_eq!(split.part_of(id), part, "{id:?} of {partitions}");
                assert!(seen.insert(id), "{id:?} in two parts");
            }
        }
        let below: HashSet<TileId> = pyramid.tiles().filter(|id| id.level <= split.level).collect();
        assert_eq!(seen, below, "{partitions} partitions");
    }
    // The coarsest level with a root per partition (levels 0–3 hold 20, 6, 2, 1 tiles); the
    // finest when none has enough.
    assert_eq!(pyramid.levels, 4);
    assert_eq!(Split::new(pyramid, 2, 4, 0).level, 2);
    assert_eq!(Split::new(pyramid, 4, 4, 0).level, 1);
    assert_eq!(Split::new(pyramid, 1, 4, 0).level, pyramid.levels - 1);
    assert_eq!(Split::new(pyramid, 1000, 4, 0).level, 0);
}

/// A source of 2^32 − 1 texels a side (its GeoTIFF's header may say so) dealt to 2^32 − 1
/// partitions: the subtree's bytes passed u64, and a partition's first root times the partitions
/// too; both panicked with overflow in a debug build (found by the overflow audit, issue 42).
#[test]
fn the_largest_layer_is_split_without_overflow() {
    let pyramid = LayerSpec::heights([u32::MAX; 2]).pyramid;
    let split = Split::new(pyramid, u32::MAX, 4, 0);
    let side = u64::from(pyramid.tile + 2 * pyramid.border + 2) << split.level;
    assert!(side * side * 4 * 4 / 3 <= SUBTREE_IMAGE_BYTES, "level {}", split.level);
    let last = split.roots(u32::MAX - 1);
    let root = last.last().copied().expect("the last partition has roots");
    assert_eq!(split.part_of(root), u32::MAX - 1);
}

#[test]
fn a_subtree_never_outgrows_its_memory_bound() {
    // A planet's imagery: 4 M texels per side.
    let spec = LayerSpec::imagery([1 << 22; 2]);
    let split = Split::new(spec.pyramid, 1, 4, 0);
    let side = u64::from(spec.pyramid.tile + 2 * spec.pyramid.border + 2) << split.level;
    assert!(side * side * 4 * 4 / 3 <= SUBTREE_IMAGE_BYTES);
    assert!(split.level >= 2, "subtrees of {} levels are too small to be worth a job", split.level);
}

#[test]
fn merged_heights_equal_the_whole_build_byte_for_byte() {
    let dir = scratch("heights");
    let spec = LayerSpec::heights([1100, 900]);
    for partitions in [1, 2, 3, 5] {
        let (whole, merged) = whole_and_merged(&dir, &spec, partitions, &source(height));
        assert!(whole == merged, "{partitions} partitions: the merged pack differs");
    }
}

#[test]
fn merged_imagery_equals_the_whole_build_byte_for_byte() {
    let dir = scratch("imagery");
    let spec = LayerSpec::imagery([1500, 1100]);
    for partitions in [2, 3] {
        let (whole, merged) = whole_and_merged(&dir, &spec, partitions, &source(rgba));
        assert!(whole == merged, "{partitions} partitions: the merged pack differs");
    }
}

#[test]
fn merged_land_cover_equals_the_whole_build_byte_for_byte() {
    let dir = scratch("landcover");
    let bar = ProgressBar::hidden();
    let size = [700, 1300];
    let codes = source(|x, y| [11u8, 21, 41, 42, 82][(hash(x / 3, y / 5) % 5) as usize]);
    let coding = LccCoding::for_codes([11, 21, 41, 42, 82]).unwrap();
    let whole = dir.join("whole.pack");
    write_lcc_layer(&whole, size, &coding, &codes, &bar).unwrap();
    let pyramid = crate::dataset::lcc::lcc_pyramid(size);
    for partitions in [1, 3, 4, 11] {
        let split = Split::new(pyramid, partitions, 4, 1);
        let parts = part_paths(&dir, partitions);
        for (part, path) in parts.iter().enumerate() {
            write_lcc_part(path, size, &coding, &split, part as u32, &codes, &bar).unwrap();
        }
        let merged = dir.join("merged.pack");
        merge_lcc(&merged, size, &coding, &split, &parts, &bar).unwrap();
        let same = std::fs::read(&whole).unwrap() == std::fs::read(&merged).unwrap();
        assert!(same, "{partitions} partitions, split at level {}: the merged pack differs", split.level);
    }
}

#[test]
fn a_part_of_another_plan_is_refused_by_name() {
    let dir = scratch("refused");
    let bar = ProgressBar::hidden();
    let spec = LayerSpec::heights([600, 600]);
    let split = Split::new(spec.pyramid, 2, 4, 0);
    let parts = part_paths(&dir, 2);
    for (part, path) in parts.iter().enumerate() {
        write_layer_part(path, &spec, &split, part as u32, source(height), &bar).unwrap();
    }
    let swapped = [parts[1].clone(), parts[0].clone()];
    let err = merge_layer::<f32>(&dir.join("m.pack"), &spec, &split, &swapped, &bar).unwrap_err();
    let message = err.to_string();
    assert!(message.contains("part-1.pack") && message.contains("partition 0"), "{message}");
}
