//! How it works: loader threads read tiles off the render thread. The render thread says, once a
//! frame, which tiles it still needs and how much (`submit`); that list *replaces* the queue of
//! requests not yet started, so a tile the view no longer wants is cancelled for free and a tile
//! that became urgent moves up at once. N workers share the queue (a binary heap under a mutex,
//! woken by a condvar) and always take the most important request left. A worker reads the tile
//! from the dataset's pack (a positioned read, so the render thread never waits on the disk),
//! which verifies its checksum, decodes it and checks its values against their recorded range
//! (`dataset::LayerPack`), and sends the owned payload back on a channel that `try_recv_all`
//! drains without blocking.
//!
//! A tile is never read twice at once: from the moment a worker takes it until the render thread
//! drains its result it is *busy*, and a re-submission of it is skipped. A tile that cannot be
//! read (missing, corrupt, out of range, or its pack changed on disk since it was opened) is
//! logged once per tile, naming the pack and the tile, and
//! comes back as an error so the cache can remember it and let the tile's ancestor stand in.
//! Dropping the `Loader` discards the queue and joins the workers (each finishes at most the tile
//! it is reading).
//!
//! Faults can be injected into the reads (`faults`, off by default): a failed or corrupt read
//! comes back as the error a real one would, a damaged one as whatever the decoders make of it
//! (an error, or a payload within the layer's checks), a slow one late.
//!
//! A cache whose texture cannot take a layer's stored blocks (BC imagery on an adapter without BC
//! sampling) is fed plain texels: the loader made with `Delivery::ImageryDecoded` decodes each
//! imagery tile on its worker thread, so the render thread only ever uploads.

use std::cmp::{Ordering, Reverse};
use std::collections::{BinaryHeap, HashMap, HashSet};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{Receiver, Sender};
use thiserror::Error;

use super::LayerKind;
use super::faults::{Fate, Faults};
use crate::dataset::{Damage, Dataset, LayerPack, PackError, TileId};

/// What the loader delivers of each tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Delivery {
    /// Every payload as the pack stores it (what caches of the packs' own formats take).
    #[default]
    Stored,
    /// Imagery decoded from its blocks to plain RGBA8 texels (`LayerPack::tile_texels`), every
    /// other layer as stored: for an imagery cache of RGBA8 over a block-compressed pack.
    ImageryDecoded,
}

/// How a loader reads.
#[derive(Debug, Clone, Copy, Default)]
pub struct LoaderOptions {
    /// Worker threads (at least one is started).
    pub threads: usize,
    /// What it delivers of block-compressed imagery.
    pub delivery: Delivery,
    /// The faults injected into its reads (none by default).
    pub faults: Faults,
}

/// Why the loader could not start, or why a tile could not be read.
#[derive(Debug, Error)]
pub enum LoaderError {
    /// The operating system refused to start a worker thread.
    #[error("starting loader thread {index}: {source}")]
    Spawn {
        /// The worker's number (its thread is named `terramp-loader-<index>`).
        index: usize,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A request named a layer the dataset does not have.
    #[error("the dataset has no {0} layer")]
    NoLayer(LayerKind),
    /// The layer's pack could not give the tile: missing, corrupt or out of range.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// A read failed by fault injection (`faults.fail`).
    #[error("injected read failure (faults.fail)")]
    Injected,
}

/// One tile the render thread wants read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileRequest {
    /// The layer to read it from.
    pub layer: LayerKind,
    /// The tile: its level, x and y in the layer's pyramid.
    pub id: TileId,
    /// Lower is more important: the tile's rank in its cache's wanted list (coarse levels first,
    /// then nearest). Ties go to heights, then imagery, then land cover, then submission order.
    pub priority: u32,
}

/// One tile read: its payload (all mips, checksum verified), or why it could not be read.
#[derive(Debug)]
pub struct Loaded {
    /// The layer it was requested from.
    pub layer: LayerKind,
    /// The tile requested.
    pub id: TileId,
    /// The payload, owned and shared without copying, or the error the cache remembers it by.
    pub result: Result<Arc<[u8]>, LoaderError>,
}

/// A queued request; the heap pops the smallest key (via `Reverse`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Queued {
    priority: u32,
    layer: LayerKind,
    order: usize,
    id: TileId,
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        (self.priority, self.layer, self.order, self.id).cmp(&(
            other.priority,
            other.layer,
            other.order,
            other.id,
        ))
    }
}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

#[derive(Default)]
struct Queue {
    pending: BinaryHeap<Reverse<Queued>>,
    /// Taken by a worker and not yet drained by `try_recv_all`.
    busy: HashSet<(LayerKind, TileId)>,
    /// Workers reading right now (their results not yet sent).
    reading: usize,
    shutdown: bool,
}

struct Shared {
    queue: Mutex<Queue>,
    wake: Condvar,
    /// Notified whenever a worker finishes a read (its result is on the channel).
    settled: Condvar,
    /// Tiles already reported unusable, so each is logged once however often it is asked for.
    reported: Mutex<HashSet<(LayerKind, TileId)>>,
}

impl Queue {
    fn is_idle(&self) -> bool {
        self.pending.is_empty() && self.reading == 0
    }
}

impl Shared {
    fn queue(&self) -> MutexGuard<'_, Queue> {
        // A worker panicking mid-read leaves the queue consistent (it only pops and counts).
        self.queue.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// Worker threads reading tiles from one dataset's packs.
pub struct Loader {
    shared: Arc<Shared>,
    results: Receiver<Loaded>,
    workers: Vec<JoinHandle<()>>,
}

impl Loader {
    /// Starts `options.threads` workers (at least one) reading from `dataset`.
    pub fn new(dataset: Arc<Dataset>, options: LoaderOptions) -> Result<Self, LoaderError> {
        let shared = Arc::new(Shared {
            queue: Mutex::new(Queue::default()),
            wake: Condvar::new(),
            settled: Condvar::new(),
            reported: Mutex::new(HashSet::new()),
        });
        let (sender, results) = crossbeam_channel::unbounded();
        let mut loader = Self { shared, results, workers: Vec::new() };
        for index in 0..options.threads.max(1) {
            let (shared, dataset, sender) = (loader.shared.clone(), dataset.clone(), sender.clone());
            let worker = std::thread::Builder::new()
                .name(format!("terramp-loader-{index}"))
                .spawn(move || work(&shared, &dataset, options, &sender))
                // Dropping `loader` here joins the workers already started.
                .map_err(|source| LoaderError::Spawn { index, source })?;
            loader.workers.push(worker);
        }
        Ok(loader)
    }

    /// Replaces the requests not yet started with `requests` (most important first by
    /// `priority`). Call it once a frame with every layer's requests, even when there are none:
    /// whatever was queued and is not in this list is cancelled. Tiles being read, or read and
    /// not yet drained, are skipped. Never waits for a read.
    pub fn submit(&self, requests: &[TileRequest]) {
        let mut queue = self.shared.queue();
        let mut best: HashMap<(LayerKind, TileId), Queued> = HashMap::with_capacity(requests.len());
        for (order, r) in requests.iter().enumerate() {
            if queue.busy.contains(&(r.layer, r.id)) {
                continue;
            }
            let entry = Queued { priority: r.priority, layer: r.layer, order, id: r.id };
            best.entry((r.layer, r.id)).and_modify(|q| *q = (*q).min(entry)).or_insert(entry);
        }
        queue.pending = best.into_values().map(Reverse).collect();
        drop(queue);
        self.shared.wake.notify_all();
    }

    /// Every tile read since the last call, in the order the workers finished. Never waits.
    pub fn try_recv_all(&self) -> Vec<Loaded> {
        let loaded: Vec<Loaded> = self.results.try_iter().collect();
        if !loaded.is_empty() {
            let mut queue = self.shared.queue();
            for l in &loaded {
                queue.busy.remove(&(l.layer, l.id));
            }
        }
        loaded
    }

    /// Nothing queued and nothing being read: every result is ready for `try_recv_all`.
    pub fn is_idle(&self) -> bool {
        self.shared.queue().is_idle()
    }

    /// Waits until a result is ready for `try_recv_all` or nothing is left to read, at most
    /// `timeout` (a guard against a hang, not a measure: the condition decides). True when the
    /// condition holds. For tools that want a view resolved, never the frame.
    pub fn wait_for_progress(&self, timeout: Duration) -> bool {
        self.wait_until(timeout, |queue| !self.results.is_empty() || queue.is_idle())
    }

    /// Waits until nothing is queued or being read (every result is then ready for
    /// `try_recv_all`), at most `timeout`, a guard against a hang. True when idle.
    pub fn wait_idle(&self, timeout: Duration) -> bool {
        self.wait_until(timeout, Queue::is_idle)
    }

    /// Waits until `done` holds of the queue, at most `timeout`. The condition is checked under
    /// the lock a finishing worker takes after sending its result, so no wake-up is lost.
    fn wait_until(&self, timeout: Duration, done: impl Fn(&Queue) -> bool) -> bool {
        let deadline = Instant::now() + timeout;
        let mut queue = self.shared.queue();
        while !done(&queue) {
            let Some(left) = deadline.checked_duration_since(Instant::now()) else { return false };
            queue = self.shared.settled.wait_timeout(queue, left).unwrap_or_else(PoisonError::into_inner).0;
        }
        true
    }

    /// Stops the workers, discarding every request not yet started, and joins them (each finishes
    /// at most the tile it is reading). Returns how many requests were discarded. Dropping the
    /// loader does the same.
    pub fn close(mut self) -> usize {
        self.shut_down()
    }

    fn shut_down(&mut self) -> usize {
        let discarded = {
            let mut queue = self.shared.queue();
            queue.shutdown = true;
            std::mem::take(&mut queue.pending).len()
        };
        self.shared.wake.notify_all();
        for worker in self.workers.drain(..) {
            // A worker that panicked has nothing left to clean up; the others exit on `shutdown`.
            let _ = worker.join();
        }
        discarded
    }

    /// Requests queued and not yet started.
    pub fn queued(&self) -> usize {
        self.shared.queue().pending.len()
    }

    /// How many distinct tiles were reported unusable so far.
    pub fn failures(&self) -> usize {
        self.shared.reported.lock().unwrap_or_else(PoisonError::into_inner).len()
    }

    /// Worker threads reading tiles (at least one).
    pub fn threads(&self) -> usize {
        self.workers.len()
    }
}

impl Drop for Loader {
    fn drop(&mut self) {
        self.shut_down();
    }
}

fn work(shared: &Shared, dataset: &Dataset, options: LoaderOptions, results: &Sender<Loaded>) {
    loop {
        let request = {
            let mut queue = shared.queue();
            loop {
                if queue.shutdown {
                    return;
                }
                if let Some(Reverse(request)) = queue.pending.pop() {
                    queue.busy.insert((request.layer, request.id));
                    queue.reading += 1;
                    break request;
                }
                queue = shared.wake.wait(queue).unwrap_or_else(PoisonError::into_inner);
            }
        };
        let result = if options.faults.any() {
            read_with_faults(dataset, request.layer, request.id, options)
        } else {
            read(dataset, request.layer, request.id, options.delivery)
        };
        if let Err(error) = &result {
            report_once(shared, request.layer, request.id, error);
        }
        // The receiver lives as long as the `Loader`, which joins us before dropping it.
        let _ = results.send(Loaded { layer: request.layer, id: request.id, result });
        shared.queue().reading -= 1;
        shared.settled.notify_all();
    }
}

fn layer(dataset: &Dataset, kind: LayerKind) -> Option<&LayerPack> {
    match kind {
        LayerKind::Height => Some(&dataset.height),
        LayerKind::Imagery => dataset.imagery.as_ref(),
        LayerKind::Landcover => dataset.landcover.as_ref(),
    }
}

/// The tile's payload as `delivery` wants it: checksum verified, decoded and checked.
pub fn read(
    dataset: &Dataset,
    kind: LayerKind,
    id: TileId,
    delivery: Delivery,
) -> Result<Arc<[u8]>, LoaderError> {
    let pack = layer(dataset, kind).ok_or(LoaderError::NoLayer(kind))?;
    Ok(match kind {
        LayerKind::Imagery => imagery_tile(pack, id, delivery)?,
        _ => pack.tile_bytes(id)?,
    })
}

/// As `read`, with the read's fate and wait from `options.faults`.
fn read_with_faults(
    dataset: &Dataset,
    kind: LayerKind,
    id: TileId,
    options: LoaderOptions,
) -> Result<Arc<[u8]>, LoaderError> {
    let (fate, wait) = options.faults.fate(kind, id);
    std::thread::sleep(wait);
    let damage = match fate {
        Fate::Read => return read(dataset, kind, id, options.delivery),
        Fate::Fail => return Err(LoaderError::Injected),
        Fate::Corrupt { at } => Damage::Caught { at },
        Fate::Damage { at } => Damage::Unseen { at },
    };
    let pack = layer(dataset, kind).ok_or(LoaderError::NoLayer(kind))?;
    let payload = pack.tile_damaged(id, damage)?;
    Ok(match (kind, options.delivery) {
        (LayerKind::Imagery, Delivery::ImageryDecoded) => pack.texels_of(payload),
        _ => payload,
    })
}

/// The imagery tile as `delivery` wants it: as stored, or decoded from its blocks.
pub fn imagery_tile(imagery: &LayerPack, id: TileId, delivery: Delivery) -> Result<Arc<[u8]>, PackError> {
    match delivery {
        Delivery::Stored => imagery.tile_bytes(id),
        Delivery::ImageryDecoded => imagery.tile_texels(id),
    }
}

fn report_once(shared: &Shared, kind: LayerKind, id: TileId, error: &LoaderError) {
    let first = shared.reported.lock().unwrap_or_else(PoisonError::into_inner).insert((kind, id));
    if first {
        eprintln!(
            "terramp: {kind} tile (level {}, x {}, y {}) unusable, its ancestor stands in: {error}",
            id.level, id.x, id.y
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queue_pops_lowest_priority_then_layer_then_order() {
        let mut heap = BinaryHeap::new();
        let q = |priority, layer, order| Reverse(Queued { priority, layer, order, id: TileId::new(0, 0, 0) });
        heap.push(q(2, LayerKind::Height, 0));
        heap.push(q(1, LayerKind::Imagery, 1));
        heap.push(q(1, LayerKind::Height, 5));
        heap.push(q(1, LayerKind::Height, 3));
        let order: Vec<(u32, LayerKind, usize)> =
            std::iter::from_fn(|| heap.pop()).map(|Reverse(q)| (q.priority, q.layer, q.order)).collect();
        assert_eq!(
            order,
            [
                (1, LayerKind::Height, 3),
                (1, LayerKind::Height, 5),
                (1, LayerKind::Imagery, 1),
                (2, LayerKind::Height, 0)
            ]
        );
    }

    #[test]
    fn dataset_can_be_shared_with_workers() {
        fn send_sync<T: Send + Sync>() {}
        send_sync::<Dataset>();
        send_sync::<Loader>();
    }
}
