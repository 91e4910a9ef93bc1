//! Tile streaming on the software adapter: loader threads (priority, cancellation, errors,
//! shutdown, never blocking) and the budgeted caches they feed (capacity, budget, eviction
//! policy, convergence, priority order, failure memory, camera jumps).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use terramp::dataset::pack::{Pack, PackWriter};
use terramp::dataset::{Dataset, IMAGERY_MIPS, Manifest, Pyramid, TileId};
use terramp::gpu::Gpu;
use terramp::streaming::{
    AreaWant, CacheStats, LayerKind, Loaded, Loader, LoaderError, LoaderOptions, TileCache, TileRequest,
    UploadBudget, tiles_over,
};

fn open(dir: &Path) -> Arc<Dataset> {
    Arc::new(Dataset::open(dir).unwrap())
}

fn cache(gpu: &Gpu, dataset: &Dataset, layer: LayerKind, slots: u32) -> TileCache {
    let (pyramid, mips, format) = match layer {
        LayerKind::Height => (dataset.height.pyramid, 1, wgpu::TextureFormat::R32Float),
        _ => {
            let p = dataset.imagery.as_ref().unwrap().pyramid;
            (p, IMAGERY_MIPS, wgpu::TextureFormat::Rgba8UnormSrgb)
        }
    };
    TileCache::new(&gpu.device, "test cache", layer, pyramid, mips, format, slots)
}

/// Every tile at `finest` and above, coarse first, then nearest to `centre` (level-0 tile units).
fn wants(p: &Pyramid, centre: [f64; 2], finest: u32) -> Vec<TileId> {
    let distance = |t: &TileId| {
        let s = f64::from(1u32 << t.level);
        ((f64::from(t.x) + 0.5) * s - centre[0]).hypot((f64::from(t.y) + 0.5) * s - centre[1])
    };
    let mut tiles: Vec<TileId> = p.tiles().filter(|t| t.level >= finest).collect();
    tiles.sort_by(|a, b| b.level.cmp(&a.level).then(distance(a).total_cmp(&distance(b))).then(a.cmp(b)));
    tiles
}

/// A guard against a hung loader, not a measure: every wait ends as soon as its condition holds.
const HANG_GUARD: Duration = Duration::from_secs(120);

/// Frames a loop may render before it calls the loader stuck (each frame waits for a read).
const FRAME_GUARD: u64 = 100_000;

fn wait_idle(loader: &Loader) {
    assert!(loader.wait_idle(HANG_GUARD), "the loader did not go idle in {HANG_GUARD:?}: hung?");
}

/// One frame as the render thread runs it: wants, one submit, drain, uploads.
fn frame(
    gpu: &Gpu,
    loader: &Loader,
    caches: &mut [(&mut TileCache, &[TileId], UploadBudget)],
    n: u64,
    wait: bool,
) -> (Vec<CacheStats>, Vec<Loaded>) {
    let mut requests: Vec<TileRequest> = Vec::new();
    for (cache, wanted, _) in caches.iter_mut() {
        requests.extend(cache.set_wanted(wanted, n));
    }
    loader.submit(&requests);
    if wait {
        wait_idle(loader);
    }
    let loaded = loader.try_recv_all();
    let stats = caches.iter_mut().map(|(c, _, budget)| c.upload(&gpu.queue, &loaded, *budget)).collect();
    gpu.queue.submit([]);
    (stats, loaded)
}

fn resident(cache: &TileCache) -> HashSet<TileId> {
    cache.resident_tiles().map(|(id, _)| id).collect()
}

/// A private copy of a dataset, to damage.
fn copy_dataset(from: &Path, name: &str) -> PathBuf {
    let to = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("streaming-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&to);
    std::fs::create_dir_all(&to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), to.join(entry.file_name())).unwrap();
    }
    to
}

/// Flips bytes in the middle of tile `id`'s stored bytes in the pack `file`.
fn corrupt_tile(dir: &Path, file: &str, pyramid: &Pyramid, id: TileId) {
    let path = dir.join(file);
    let span = Pack::open(&path).unwrap().stored_span(pyramid.tile_index(id).unwrap()).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let at = ((span.start + span.end) / 2) as usize;
    for b in &mut bytes[at..(at + 16).min(span.end as usize)] {
        *b ^= 0x5a;
    }
    std::fs::write(&path, bytes).unwrap();
}

/// Rewrites the pack at `path` with tile `index` never written.
fn rewrite_without(path: &Path, index: u64) {
    let old = Pack::open(path).unwrap();
    let new_path = path.with_extension("new");
    let writer = PackWriter::create(&new_path, old.tile_bytes(), old.tile_count(), old.codec()).unwrap();
    for i in (0..old.tile_count()).filter(|&i| i != index) {
        writer.write_tile(i, &old.tile(i).unwrap(), old.tile_range(i).unwrap()).unwrap();
    }
    writer.finish().unwrap();
    drop(old);
    std::fs::rename(new_path, path).unwrap();
}

#[test]
fn loader_serves_most_important_first_and_never_blocks() {
    let dataset = open(&terramp_testkit::synth_dataset(600, 11));
    let pyramid = dataset.imagery.as_ref().unwrap().pyramid;
    let loader = Loader::new(dataset.clone(), LoaderOptions { threads: 1, ..Default::default() }).unwrap();
    // Priorities in a scrambled order; one worker must return them sorted.
    let tiles: Vec<TileId> = pyramid.tiles().collect();
    let requests: Vec<TileRequest> = (0..tiles.len())
        .map(|i| TileRequest {
            layer: LayerKind::Imagery,
            id: tiles[i],
            priority: ((i * 17) % tiles.len()) as u32,
        })
        .collect();
    loader.submit(&requests);
    let early = loader.try_recv_all();
    // Had submit (or the drain) waited for the reads, one worker would be done with them all.
    assert!(!loader.is_idle() && early.len() < tiles.len(), "submit waited for the reads");
    wait_idle(&loader);
    let mut loaded = early;
    loaded.extend(loader.try_recv_all());
    let priority: HashMap<TileId, u32> = requests.iter().map(|r| (r.id, r.priority)).collect();
    let order: Vec<u32> = loaded.iter().map(|l| priority[&l.id]).collect();
    assert_eq!(order, (0..tiles.len() as u32).collect::<Vec<_>>());
    for l in &loaded {
        let payload = l.result.as_ref().unwrap();
        assert_eq!(&payload[..], &*dataset.imagery.as_ref().unwrap().tile_bytes(l.id).unwrap());
    }
    // Re-submitting replaces the queue: at most the tile being read is left of the old one, and
    // a tile listed twice is read once.
    loader.submit(&requests);
    let first = TileRequest { layer: LayerKind::Height, id: TileId::new(0, 0, 0), priority: 5 };
    loader.submit(&[first, TileRequest { priority: 1, ..first }]);
    assert!(loader.queued() <= 1);
    wait_idle(&loader);
    let loaded = loader.try_recv_all();
    assert!(loaded.iter().filter(|l| l.layer == LayerKind::Imagery).count() < tiles.len() / 2);
    assert_eq!(loaded.iter().filter(|l| l.layer == LayerKind::Height).count(), 1);
}

#[test]
fn loader_reports_missing_tiles_and_shuts_down_cleanly() {
    let source = terramp_testkit::synth_dataset(600, 11);
    let dir = copy_dataset(&source, "missing");
    // No land-cover layer, and one height tile never written (its index entry cleared).
    let manifest_path = dir.join("manifest.toml");
    let mut manifest: Manifest = toml::from_str(&std::fs::read_to_string(&manifest_path).unwrap()).unwrap();
    manifest.landcover = None;
    std::fs::write(&manifest_path, toml::to_string(&manifest).unwrap()).unwrap();
    let unwritten = TileId::new(0, 1, 0);
    let index = manifest.height.pyramid.tile_index(unwritten).unwrap();
    rewrite_without(&dir.join(&manifest.height.pack), index);

    let loader = Loader::new(open(&dir), LoaderOptions { threads: 2, ..Default::default() }).unwrap();
    let ask = |layer, id| TileRequest { layer, id, priority: 0 };
    let outside = TileId::new(0, 99, 99);
    loader.submit(&[
        ask(LayerKind::Height, unwritten),
        ask(LayerKind::Imagery, outside),
        ask(LayerKind::Landcover, TileId::new(0, 0, 0)),
        ask(LayerKind::Height, TileId::new(1, 0, 0)),
    ]);
    wait_idle(&loader);
    let loaded: HashMap<(LayerKind, TileId), Loaded> =
        loader.try_recv_all().into_iter().map(|l| ((l.layer, l.id), l)).collect();
    assert_eq!(loaded.len(), 4);
    let error = |layer, id| loaded[&(layer, id)].result.as_ref().err().map(ToString::to_string);
    assert!(error(LayerKind::Height, unwritten).is_some_and(|e| e.contains("never written")));
    assert!(error(LayerKind::Imagery, outside).is_some_and(|e| e.contains("out of range")));
    assert!(matches!(
        loaded[&(LayerKind::Landcover, TileId::new(0, 0, 0))].result,
        Err(LoaderError::NoLayer(_))
    ));
    assert!(loaded[&(LayerKind::Height, TileId::new(1, 0, 0))].result.is_ok());
    // Asked again, the same tile comes back as an error again but is logged only once.
    loader.submit(&[ask(LayerKind::Height, unwritten)]);
    wait_idle(&loader);
    assert!(loader.try_recv_all()[0].result.is_err());
    assert_eq!(loader.failures(), 3);

    // Closing a loader with a full queue discards the queue and joins the workers, which finish
    // at most the tile each is reading: most of the queue is still there to discard (to empty half
    // of it, two workers would have to copy and checksum some 30 MB between these two lines).
    let pyramid = manifest.imagery.as_ref().unwrap().pyramid;
    let busy = Loader::new(open(&dir), LoaderOptions { threads: 2, ..Default::default() }).unwrap();
    let all: Vec<TileRequest> = pyramid.tiles().map(|id| ask(LayerKind::Imagery, id)).collect();
    busy.submit(&all);
    let discarded = busy.close();
    assert!(discarded > all.len() / 2, "{discarded} of {} requests discarded", all.len());
}

#[test]
fn budget_and_eviction_rules_hold_over_a_moving_view() {
    let gpu = terramp_testkit::gpu();
    let dataset = open(&terramp_testkit::synth_dataset(600, 11));
    let loader = Loader::new(dataset.clone(), LoaderOptions { threads: 2, ..Default::default() }).unwrap();
    let mut imagery = cache(&gpu, &dataset, LayerKind::Imagery, 12);
    let mut heights = cache(&gpu, &dataset, LayerKind::Height, 6);
    // Imagery is held back by its tile count, heights by their bytes (262 KiB a tile).
    let imagery_budget = UploadBudget { tiles: 3, bytes: 64 << 20 };
    let height_budget = UploadBudget { tiles: 8, bytes: 600 << 10 };
    let (ip, hp) = (imagery.pyramid().to_owned(), heights.pyramid().to_owned());
    for n in 0..80u64 {
        let t = n as f64 * 0.15;
        let centre = [2.5 + 2.4 * t.cos(), 2.5 + 2.4 * (1.3 * t).sin()];
        // More than fits: the caches must choose, and evict needed tiles for more needed ones.
        let want_imagery: Vec<TileId> = wants(&ip, centre, 0).into_iter().take(18).collect();
        let want_heights: Vec<TileId> =
            wants(&hp, [centre[0] / 2.0, centre[1] / 2.0], 0).into_iter().take(9).collect();
        let before = [resident(&imagery), resident(&heights)];
        let (stats, _) = frame(
            &gpu,
            &loader,
            &mut [
                (&mut imagery, &want_imagery, imagery_budget),
                (&mut heights, &want_heights, height_budget),
            ],
            n,
            n % 3 != 2,
        );
        let caches = [(&imagery, &want_imagery, imagery_budget), (&heights, &want_heights, height_budget)];
        for (k, (cache, wanted, budget)) in caches.into_iter().enumerate() {
            let (after, s) = (resident(cache), &stats[k]);
            assert!(after.len() <= cache.capacity() && s.resident == after.len(), "{s:?}");
            assert!(
                s.uploaded <= 1 || (s.uploaded <= budget.tiles && s.bytes_uploaded <= budget.bytes),
                "{s:?}"
            );
            let rank: HashMap<TileId, usize> =
                wanted.iter().enumerate().rev().map(|(i, id)| (*id, i)).collect();
            let uploaded: Vec<&TileId> = after.difference(&before[k]).collect();
            for gone in before[k].difference(&after) {
                let Some(&r) = rank.get(gone) else { continue };
                assert!(
                    after.iter().all(|id| rank.contains_key(id)),
                    "needed {gone:?} evicted, unneeded kept"
                );
                assert!(
                    uploaded.iter().all(|id| rank[*id] < r),
                    "needed {gone:?} evicted for a less needed tile"
                );
            }
        }
    }
}

#[test]
fn fixed_view_converges_then_uploads_nothing() {
    let gpu = terramp_testkit::gpu();
    let dataset = open(&terramp_testkit::synth_dataset(600, 11));
    let loader = Loader::new(dataset.clone(), LoaderOptions { threads: 2, ..Default::default() }).unwrap();
    let mut imagery = cache(&gpu, &dataset, LayerKind::Imagery, 24);
    let wanted: Vec<TileId> = wants(imagery.pyramid(), [1.0, 3.0], 0).into_iter().take(20).collect();
    let budget = UploadBudget { tiles: 4, bytes: 32 << 20 };
    let mut n = 0;
    loop {
        let (stats, _) = frame(&gpu, &loader, &mut [(&mut imagery, &wanted, budget)], n, false);
        if stats[0].needed_resident == wanted.len() {
            break;
        }
        assert!(n < FRAME_GUARD, "not converged after {n} frames: {:?}", stats[0]);
        loader.wait_for_progress(HANG_GUARD);
        n += 1;
    }
    for k in 1..=20 {
        let (stats, _) = frame(&gpu, &loader, &mut [(&mut imagery, &wanted, budget)], n + k, false);
        let s = &stats[0];
        assert_eq!(
            (s.uploaded, s.requested, s.in_flight, s.evicted, s.needed_resident),
            (0, 0, 0, 0, 20),
            "{s:?}"
        );
    }
    gpu.check().unwrap();
}

#[test]
fn coarse_and_near_tiles_arrive_first() {
    let gpu = terramp_testkit::gpu();
    let dataset = open(&terramp_testkit::synth_dataset(600, 11));
    // One worker serves in strict priority order; one tile a frame makes the order visible.
    let loader = Loader::new(dataset.clone(), LoaderOptions { threads: 1, ..Default::default() }).unwrap();
    let mut imagery = cache(&gpu, &dataset, LayerKind::Imagery, 48);
    let wanted = wants(imagery.pyramid(), [4.5, 0.5], 0);
    let budget = UploadBudget { tiles: 1, bytes: 1 };
    let mut order = Vec::new();
    for n in 0..FRAME_GUARD {
        let before = resident(&imagery);
        frame(&gpu, &loader, &mut [(&mut imagery, &wanted, budget)], n, false);
        order.extend(resident(&imagery).difference(&before).copied());
        if order.len() == wanted.len() {
            break;
        }
        loader.wait_for_progress(HANG_GUARD);
    }
    assert_eq!(order, wanted, "uploads follow the wanted order");
    assert!(order.windows(2).all(|w| w[0].level >= w[1].level));
    let last_level0 = order.iter().rev().find(|t| t.level == 0).unwrap();
    assert_eq!((last_level0.x, last_level0.y), (0, 4), "the farthest level-0 tile comes last");
}

#[test]
fn corrupt_tiles_fail_once_and_their_ancestor_stands_in() {
    let source = terramp_testkit::synth_dataset(600, 11);
    let dir = copy_dataset(&source, "corrupt");
    let clean = open(&source);
    let (ip, hp) = (clean.imagery.as_ref().unwrap().pyramid, clean.height.pyramid);
    let bad = TileId::new(0, 1, 1);
    let gpu = terramp_testkit::gpu();
    let mut imagery = cache(&gpu, &clean, LayerKind::Imagery, 48);
    let mut heights = cache(&gpu, &clean, LayerKind::Height, 16);
    corrupt_tile(&dir, "imagery.pack", &ip, bad);
    corrupt_tile(&dir, "height.pack", &hp, bad);
    let loader = Loader::new(open(&dir), LoaderOptions { threads: 2, ..Default::default() }).unwrap();
    let (want_imagery, want_heights) = (wants(&ip, [1.5, 1.5], 0), wants(&hp, [1.5, 1.5], 0));
    let mut errors = Vec::new();
    let mut failed = [0, 0];
    for n in 0..40 {
        let (stats, loaded) = frame(
            &gpu,
            &loader,
            &mut [
                (&mut imagery, &want_imagery, UploadBudget::UNLIMITED),
                (&mut heights, &want_heights, UploadBudget::UNLIMITED),
            ],
            n,
            true,
        );
        errors.extend(loaded.iter().filter(|l| l.result.is_err()).map(|l| (l.layer, l.id)));
        failed = [failed[0] + stats[0].failed, failed[1] + stats[1].failed];
        if n > 2 {
            assert_eq!((stats[0].requested, stats[1].requested), (0, 0), "a failed tile was asked for again");
        }
    }
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert!(errors.contains(&(LayerKind::Imagery, bad)) && errors.contains(&(LayerKind::Height, bad)));
    assert_eq!((failed, loader.failures()), ([1, 1], 2));
    for (cache, wanted) in [(&imagery, &want_imagery), (&heights, &want_heights)] {
        assert!(cache.is_failed(bad) && cache.slot_of(bad).is_none());
        assert_eq!(cache.resident_ancestor(bad).map(|(id, _)| id), Some(TileId::new(1, 0, 0)));
        assert_eq!(resident(cache).len(), wanted.len() - 1, "every other tile loads");
        let child = TileId::new(0, 2, 2);
        assert_eq!(cache.resident_ancestor(child).map(|(id, _)| id), Some(child));
    }
    gpu.check().unwrap();
}

#[test]
fn camera_jump_converges_within_the_budget() {
    let gpu = terramp_testkit::gpu();
    let dataset = open(&terramp_testkit::synth_dataset(600, 11));
    let loader = Loader::new(dataset.clone(), LoaderOptions { threads: 2, ..Default::default() }).unwrap();
    let mut imagery = cache(&gpu, &dataset, LayerKind::Imagery, 16);
    let texel_m = dataset.manifest.imagery.as_ref().unwrap().texel_m;
    let view = |min: f64, max: f64| {
        let area = AreaWant { min_m: [min; 2], max_m: [max; 2], levels: [0, 0], distance_m: 10.0 };
        tiles_over(imagery.pyramid(), texel_m * f64::from(imagery.pyramid().tile), &[area])
    };
    let (a, b) = (view(0.0, 2000.0), view(4000.0, 5900.0));
    assert!(a.len() <= 16 && b.len() <= 16 && a.iter().filter(|t| !b.contains(t)).count() >= 5);
    let budget = UploadBudget { tiles: 2, bytes: 32 << 20 };
    let mut n = 0;
    for wanted in [&a, &b] {
        let new = wanted.iter().filter(|t| imagery.slot_of(**t).is_none()).count();
        let limit = new.div_ceil(budget.tiles) + 3;
        let mut frames = 0;
        loop {
            let (stats, _) = frame(&gpu, &loader, &mut [(&mut imagery, wanted, budget)], n, true);
            n += 1;
            frames += 1;
            assert!(stats[0].resident <= imagery.capacity());
            if stats[0].needed_resident == wanted.len() {
                break;
            }
            assert!(frames < limit, "{new} new tiles not resident after {frames} frames: {:?}", stats[0]);
        }
    }
}

#[test]
fn load_now_makes_the_view_resident_at_once() {
    let gpu = terramp_testkit::gpu();
    let dataset = open(&terramp_testkit::synth_dataset(600, 11));
    let mut heights = cache(&gpu, &dataset, LayerKind::Height, 16);
    let wanted = wants(heights.pyramid(), [0.0, 0.0], 0);
    let stats = heights.load_now(&gpu.queue, &wanted, 0, |id| dataset.height.tile_bytes(id));
    assert_eq!((stats.needed_resident, stats.uploaded, stats.in_flight), (wanted.len(), wanted.len(), 0));
    let again = heights.load_now(&gpu.queue, &wanted, 1, |id| dataset.height.tile_bytes(id));
    assert_eq!((again.uploaded, again.requested), (0, 0));
    gpu.check().unwrap();
}
