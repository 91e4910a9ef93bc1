//! What reading tiles with positioned reads costs against a memory mapping, per layer of each
//! dataset given: every tile's stored bytes checked against their CRC-32 straight from a mapping
//! of the pack (how packs were read before, mapped once and kept), then read with `pread` and
//! checked (`Pack::read_stored`, how they are read now), and the whole read a loader worker makes
//! (`streaming::loader::read`: read, checksum, decode, range check). Each is the median of `RUNS`
//! passes over every tile, the page cache warm (a first pass, untimed, reads every file).
//! `cargo bench --bench tile_reads -- DATASET...`; `RUNS` (default 7) sets the passes.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

use std::path::Path;
use std::time::Instant;

use terramp::dataset::{Dataset, LayerPack, TileId};
use terramp::streaming::loader::read;
use terramp::streaming::{Delivery, LayerKind};

fn main() {
    let dirs: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    assert!(!dirs.is_empty(), "usage: tile_reads DATASET...");
    let runs: usize = std::env::var("RUNS").ok().and_then(|v| v.parse().ok()).unwrap_or(7);
    println!("Median of {runs} passes, µs per tile, page cache warm.\n");
    println!(
        "| dataset | layer | tiles | stored bytes (mean) | mapped + CRC | pread + CRC | loader read (pread, decode, check) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for dir in &dirs {
        let dataset = Dataset::open(Path::new(dir)).unwrap();
        let name = Path::new(dir).file_name().unwrap().to_string_lossy().into_owned();
        for kind in [LayerKind::Height, LayerKind::Imagery, LayerKind::Landcover] {
            let Some(layer) = (match kind {
                LayerKind::Height => Some(&dataset.height),
                LayerKind::Imagery => dataset.imagery.as_ref(),
                LayerKind::Landcover => dataset.landcover.as_ref(),
            }) else {
                continue;
            };
            let row = measure(dir, kind, layer, runs);
            println!("| {name} | {kind} | {row} |");
        }
    }
}

fn tiles(layer: &LayerPack) -> Vec<(TileId, u64)> {
    let p = &layer.pyramid;
    (0..p.levels)
        .flat_map(|level| {
            let [nx, ny] = p.tiles_at(level);
            (0..ny).flat_map(move |y| (0..nx).map(move |x| TileId::new(level, x, y)))
        })
        .map(|id| (id, p.tile_index(id).unwrap()))
        .collect()
}

/// The median over `runs` of `pass`'s time per tile, µs, after one untimed pass.
fn per_tile_us(runs: usize, tiles: usize, mut pass: impl FnMut() -> u64) -> f64 {
    let mut sink = pass();
    let mut us: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            sink = sink.wrapping_add(pass());
            start.elapsed().as_secs_f64() * 1e6 / tiles as f64
        })
        .collect();
    std::hint::black_box(sink);
    us.sort_by(f64::total_cmp);
    us[us.len() / 2]
}

fn measure(dir: &str, kind: LayerKind, layer: &LayerPack, runs: usize) -> String {
    let pack = layer.pack();
    let ids = tiles(layer);
    let spans: Vec<std::ops::Range<usize>> = ids
        .iter()
        .map(|&(_, i)| pack.stored_span(i).unwrap())
        .map(|s| s.start as usize..s.end as usize)
        .collect();
    let stored_mean = spans.iter().map(|s| s.len()).sum::<usize>() / spans.len();
    let file = std::fs::File::open(pack.path()).unwrap();
    // SAFETY: the bench's own read-only mapping of a pack nothing writes while it runs.
    let map = unsafe { memmap2::Mmap::map(&file) }.unwrap();
    let mapped = per_tile_us(runs, ids.len(), || {
        spans.iter().map(|s| u64::from(crc32fast::hash(&map[s.clone()]))).sum()
    });
    let pread = per_tile_us(runs, ids.len(), || {
        ids.iter().map(|&(_, i)| pack.read_stored(i).unwrap().len() as u64).sum()
    });
    // A dataset opened afresh for each pass, before the timing: no tile is in its recent tiles.
    let mut fresh = (0..=runs).map(|_| Dataset::open(Path::new(dir)).unwrap());
    let loader = per_tile_us(runs, ids.len(), || {
        let dataset = fresh.next().unwrap();
        ids.iter().map(|&(id, _)| read(&dataset, kind, id, Delivery::Stored).unwrap().len() as u64).sum()
    });
    format!("{} | {stored_mean} | {mapped:.1} | {pread:.1} | {loader:.1}", ids.len())
}
