//! Fault injection into tile streaming (`[faults]`). Read by the loader, every tile of every layer
//! fails exactly as it was made to: an injected failure or a corrupt read always, damage under a
//! matching checksum when a decoder or a layer's range check refuses it, and nothing else; what
//! damage decodes passes the layer's invariants. A flight (BC7 imagery decoded on the loader's
//! threads) whose reads fail, arrive corrupt or damaged, or late, never shows a hole (ancestors
//! stand in: no frame shows less ground than the same flight's without faults), never shows a
//! tile made to fail, remembers as failed only tiles made to fail, shows some damaged tiles as
//! they decoded and refuses others, and keeps the loader's queue within the caches' slots.
#![allow(clippy::unwrap_used, reason = "tests")]

use std::collections::HashSet;
use std::sync::Arc;
use std::time::Duration;

use glam::DVec3;
use terramp::config::{FaultSettings, ImageryBlocks};
use terramp::dataset::{Dataset, ImageryFormat, LayerPack, PackError, Pyramid, TileId};
use terramp::streaming::faults::Fate;
use terramp::streaming::loader::read;
use terramp::streaming::{Delivery, Faults, LayerKind, Loader, LoaderError, LoaderOptions, TileRequest};
use terramp::synth::SynthParams;
use terramp_testkit::camera::at_grid;
use terramp_testkit::{ground_settings, renderer, synth_dataset_with};

const FRAMES: usize = 100;
const LAYERS: [LayerKind; 3] = [LayerKind::Height, LayerKind::Imagery, LayerKind::Landcover];

/// Every tile of `pyramid`.
fn tiles(pyramid: &Pyramid) -> impl Iterator<Item = TileId> + '_ {
    (0..pyramid.levels).flat_map(move |level| {
        let [nx, ny] = pyramid.tiles_at(level);
        (0..ny).flat_map(move |y| (0..nx).map(move |x| TileId::new(level, x, y)))
    })
}

fn layer(dataset: &Dataset, kind: LayerKind) -> &LayerPack {
    match kind {
        LayerKind::Height => &dataset.height,
        LayerKind::Imagery => dataset.imagery.as_ref().unwrap(),
        LayerKind::Landcover => dataset.landcover.as_ref().unwrap(),
    }
}

/// The first value of a delivered payload outside its tile's recorded range (heights: samples;
/// land cover: every palette index its words hold), read the dataset's own way, or `None`.
fn outside_range(dataset: &Dataset, kind: LayerKind, id: TileId, payload: &[u8]) -> Option<f64> {
    let [min, max] = layer(dataset, kind).tile_range(id).unwrap()?.map(f64::from);
    let values: Vec<f64> = match kind {
        LayerKind::Height => {
            bytemuck::pod_collect_to_vec::<u8, f32>(payload).into_iter().map(f64::from).collect()
        }
        LayerKind::Landcover => {
            let coding = dataset.lcc_coding().unwrap();
            let words = payload.chunks_exact(coding.word_bytes());
            let word = |w: &[u8]| w.iter().rev().fold(0u32, |v, &b| v << 8 | u32::from(b));
            words
                .flat_map(|w| (0..4).map(move |k| coding.decode(id.level, word(w), [k & 1, k >> 1])))
                .map(f64::from)
                .collect()
        }
        LayerKind::Imagery => return None,
    };
    values.into_iter().find(|v| !(min <= *v && *v <= max))
}

/// What damage did to one layer's reads.
#[derive(Debug, Default)]
struct Damaged {
    /// Decoded to a payload unlike the tile's, within the layer's checks, and delivered.
    delivered: usize,
    /// Refused by the codec (`Corrupt`: zstd, a predictor, the size).
    undecodable: usize,
    /// Decoded, and refused by the range check (`OutsideRange`).
    outside: usize,
}

#[test]
fn every_tile_read_through_faults_fails_exactly_as_it_was_made_to() {
    // Damage is most of the fates, so that each outcome of it is met in every layer; every layer
    // of a dataset with RGBA8 imagery, then the imagery of two stored in BC7 and BC1 blocks,
    // decoded on the loader's threads (their heights and land cover are the first's).
    let faults = FaultSettings { fail: 0.15, corrupt: 0.15, damage: 0.75, delay_ms: 0, seed: 0 };
    let imagery = [LayerKind::Imagery];
    let cases = [
        (ImageryFormat::Rgba8, Delivery::Stored, &LAYERS[..]),
        (ImageryFormat::Bc7, Delivery::ImageryDecoded, &imagery[..]),
        (ImageryFormat::Bc1, Delivery::ImageryDecoded, &imagery[..]),
    ];
    let mut damaged: Vec<(LayerKind, ImageryFormat, Damaged)> = Vec::new();
    for (format, delivery, kinds) in cases {
        let params = SynthParams { size: 600, seed: 4, imagery_format: format, ..Default::default() };
        let dataset = Arc::new(Dataset::open(&synth_dataset_with(&params)).unwrap());
        for seed in 0..4 {
            let faults = FaultSettings { seed, ..faults };
            let options = LoaderOptions { threads: 2, delivery, faults: Faults::new(&faults) };
            let loader = Loader::new(dataset.clone(), options).unwrap();
            let requests: Vec<TileRequest> = kinds
                .iter()
                .flat_map(|&kind| {
                    tiles(&layer(&dataset, kind).pyramid).map(move |id| (kind, id)).collect::<Vec<_>>()
                })
                .enumerate()
                .map(|(priority, (layer, id))| TileRequest { layer, id, priority: priority as u32 })
                .collect();
            loader.submit(&requests);
            // A guard against a hang: idleness decides.
            assert!(loader.wait_idle(Duration::from_secs(600)));
            let loaded = loader.try_recv_all();
            assert_eq!(loaded.len(), requests.len(), "every tile read once");
            for &kind in kinds {
                if !damaged.iter().any(|(k, f, _)| *k == kind && *f == format) {
                    damaged.push((kind, format, Damaged::default()));
                }
            }
            for l in loaded {
                let (fate, _) = options.faults.fate(l.layer, l.id);
                let clean = read(&dataset, l.layer, l.id, delivery).unwrap();
                let index = layer(&dataset, l.layer).pyramid.tile_index(l.id).unwrap();
                let what = format!("{format:?} seed {seed}: {} tile {:?} ({fate:?})", l.layer, l.id);
                let tally =
                    &mut damaged.iter_mut().find(|(k, f, _)| *k == l.layer && *f == format).unwrap().2;
                match (fate, l.result) {
                    (Fate::Read, Ok(payload)) => assert!(payload == clean, "{what}: not the tile"),
                    (Fate::Fail, Err(LoaderError::Injected)) => {}
                    (Fate::Corrupt { .. }, Err(LoaderError::Pack(PackError::Corrupt { index: i, .. })))
                        if i == index => {}
                    (Fate::Damage { .. }, Ok(payload)) => {
                        assert_eq!(payload.len(), clean.len(), "{what}");
                        assert_eq!(
                            outside_range(&dataset, l.layer, l.id, &payload),
                            None,
                            "{what}: delivered"
                        );
                        // One flipped byte whose checksum matches may leave the payload as it was
                        // (a byte zstd does not read back); that is no damage delivered.
                        tally.delivered += usize::from(payload != clean);
                    }
                    (Fate::Damage { .. }, Err(LoaderError::Pack(PackError::Corrupt { index: i, .. })))
                        if i == index =>
                    {
                        tally.undecodable += 1
                    }
                    (
                        Fate::Damage { .. },
                        Err(LoaderError::Pack(PackError::OutsideRange { index: i, .. })),
                    ) if i == index => tally.outside += 1,
                    (fate, result) => panic!("{what}: {fate:?} read as {:?}", result.map(|p| p.len())),
                }
            }
        }
    }
    for (kind, format, tally) in &damaged {
        eprintln!("{format:?} {kind}: damage {tally:?}");
        assert!(tally.delivered > 0 && tally.undecodable > 0, "{format:?} {kind}: {tally:?}");
        // Only heights and land cover record a range to check.
        let ranged = *kind != LayerKind::Imagery;
        assert_eq!(tally.outside > 0, ranged, "{format:?} {kind}: {tally:?}");
    }
}

/// What a flight saw: per frame, the pixels showing no ground; the failures counted; the longest
/// queue of one cache; the damaged tiles shown (resident in some frame), by layer.
struct Flight {
    renderer: terramp::frame::Renderer,
    no_ground_px: Vec<usize>,
    failed: usize,
    worst_queue: usize,
    damaged_shown: HashSet<(LayerKind, TileId)>,
}

/// Flies `FRAMES` frames with `faults` over ground that fills every view, checking that no pixel
/// is black, that each cache's queue fits its slots, and that no tile made to fail is resident
/// (but for the pinned ones, which the loader does not read).
fn fly(faults: &FaultSettings) -> Flight {
    // Imagery in BC7 blocks, decoded to RGBA8 on the loader's threads on any adapter: the block
    // decoder meets the damaged blocks.
    let params =
        SynthParams { size: 2048, seed: 9, imagery_format: ImageryFormat::Bc7, ..Default::default() };
    let dataset = synth_dataset_with(&params);
    let mut settings = ground_settings(320, 180);
    settings.imagery.blocks = ImageryBlocks::Decode;
    settings.faults = *faults;
    let injected = Faults::new(faults);
    let mut r = renderer(&dataset, settings);
    assert_eq!(r.tile_caches()[1].format(), wgpu::TextureFormat::Rgba8UnormSrgb);
    let [w, h] = r.dataset.manifest.extent_m();
    let (mut failed, mut worst_queue, mut no_ground_px) = (0usize, 0usize, Vec::new());
    let mut damaged_shown = HashSet::new();
    // The pinned tiles, loaded when the renderer was made, with no fault: faults are injected
    // into the loader's reads.
    let pinned: HashSet<(LayerKind, TileId)> =
        r.tile_caches().iter().flat_map(|c| c.resident_tiles().map(|(id, _)| (c.layer(), id))).collect();
    assert!(!pinned.is_empty());
    for frame in 0..FRAMES {
        // Low and looking down across the dataset, so that every pixel must show ground.
        let f = frame as f64 / (FRAMES - 1) as f64;
        let at = DVec3::new((0.15 + 0.6 * f) * w, (0.2 + 0.5 * f) * h, 900.0);
        let camera = at_grid(&r, at, 45.0 + 30.0 * f, -60.0);
        let report = r.render(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        no_ground_px.push(depth.iter().filter(|&&d| d == 0.0).count());
        let colour = r.read_colour().unwrap();
        let black = colour.pixels().filter(|p| p[0] == 0 && p[1] == 0 && p[2] == 0).count();
        assert_eq!(black, 0, "{faults:?} frame {frame}: {black} black pixels");
        for (stats, cache) in [report.height, report.imagery, report.landcover].iter().zip(r.tile_caches()) {
            failed += stats.failed;
            let queue = stats.in_flight + stats.staged;
            worst_queue = worst_queue.max(queue);
            assert!(
                queue <= cache.capacity(),
                "frame {frame}: {queue} tiles queued for {} slots",
                cache.capacity()
            );
            let layer = cache.layer();
            for (id, _) in cache.resident_tiles().filter(|&(id, _)| !pinned.contains(&(layer, id))) {
                match injected.fate(layer, id).0 {
                    Fate::Read => {}
                    Fate::Damage { .. } => _ = damaged_shown.insert((layer, id)),
                    fate => {
                        panic!("frame {frame}: {layer} tile {id:?} is shown, though made to fail ({fate:?})")
                    }
                }
            }
        }
    }
    Flight { renderer: r, no_ground_px, failed, worst_queue, damaged_shown }
}

#[test]
fn a_flight_over_failing_corrupt_damaged_and_slow_reads_shows_no_hole() {
    // The control: the same flight with no fault. It fails nothing, and shows ground everywhere
    // but for one pixel of frame 70, (214, 10): not a crack in the mesh but a sliver of LOD 1's
    // finishing morph that lavapipe's back-face cull drops though its rasteriser finds it
    // front-facing (the terrain pipeline's `cull_mode` says why the cull stays).
    let control = fly(&FaultSettings { seed: 3, ..FaultSettings::default() });
    assert_eq!(control.failed, 0);
    assert!(control.no_ground_px.iter().all(|&px| px <= 2), "{:?}", control.no_ground_px);
    let faults = FaultSettings { fail: 0.2, corrupt: 0.15, damage: 0.3, delay_ms: 12, seed: 3 };
    let Flight { renderer: r, no_ground_px, failed, worst_queue, damaged_shown } = fly(&faults);
    for (frame, (&px, &control_px)) in no_ground_px.iter().zip(&control.no_ground_px).enumerate() {
        assert!(px <= control_px, "frame {frame}: {px} pixels show no ground, {control_px} without faults");
    }
    // The tiles remembered as failed were all made to fail, some of each kind; the other
    // direction, that none made to fail was ever shown, `fly` checked frame by frame.
    let injected = Faults::new(&faults);
    let mut fates = Vec::new();
    for cache in r.tile_caches() {
        let layer = cache.layer();
        for id in tiles(cache.pyramid()).filter(|&id| cache.is_failed(id)) {
            let (fate, _) = injected.fate(layer, id);
            assert_ne!(fate, Fate::Read, "{layer} tile {id:?} failed with no fault injected");
            fates.push((layer, fate));
        }
    }
    assert_eq!(fates.len(), failed, "every failure counted once");
    let failed_as = |f: fn(&Fate) -> bool| fates.iter().filter(|(_, fate)| f(fate)).count();
    let [fail, corrupt, damage] = [
        failed_as(|f| *f == Fate::Fail),
        failed_as(|f| matches!(f, Fate::Corrupt { .. })),
        failed_as(|f| matches!(f, Fate::Damage { .. })),
    ];
    assert!(fail > 0 && corrupt > 0 && damage > 0, "{fates:?}");
    // Damaged tiles both refused by a decoder or a range check, and shown as they decoded, in
    // the two layers a ground flight streams most.
    for layer in LAYERS {
        let refused = fates.iter().filter(|(l, f)| *l == layer && matches!(f, Fate::Damage { .. })).count();
        let shown = damaged_shown.iter().filter(|(l, _)| *l == layer).count();
        eprintln!("{layer}: {refused} damaged tiles refused, {shown} shown");
        if layer != LayerKind::Landcover {
            assert!(refused > 0 && shown > 0, "{layer}: {refused} damaged tiles refused, {shown} shown");
        }
    }
    eprintln!(
        "{failed} tiles failed over {FRAMES} frames ({fail} failed reads, {corrupt} corrupt, {damage} damaged); \
         {} damaged tiles shown; at most {worst_queue} tiles queued in one cache",
        damaged_shown.len()
    );
}
