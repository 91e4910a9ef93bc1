//! How it works: the CPU bookkeeping of one tile cache, apart from the GPU so its policy can be
//! tested without a device. Each frame, `set_wanted` records what the frame needs, with each
//! tile's rank in the wanted list (0 = most important: coarse levels first, then nearest). Only
//! the first `capacity` tiles that have not failed can ever be resident together, so those are
//! the *fitting* tiles; the ones neither resident, arrived nor failed become loader requests (the
//! paper's push list: the current list minus what is already there or on its way). Tiles the
//! frame no longer fits are forgotten from the in-flight and arrived sets, so the loader's queue
//! and the upload queue only ever hold what the view wants now.
//!
//! Arrivals wait in `staged` (so a tile read once is never read again because the upload budget
//! ran out) and go up most important first, at most the budget per frame but always at least one
//! tile, so progress never stalls. A slot comes from the free stack (the paper's cacheList) while
//! there is one, else from the resident tile this frame does not need that was needed least
//! recently (finer first among equals: coarse tiles stand in for more), else from the least
//! important needed tile *less* important than the arrival. A needed tile is never evicted for
//! one needed less; if nothing qualifies, the arrival is dropped. A failed tile is remembered:
//! never requested again, never resident, and its resident ancestor stands in.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use super::LayerKind;
use super::loader::{Loaded, TileRequest};
use crate::config::CacheSettings;
use crate::dataset::TileId;

/// What one frame did to a cache.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct CacheStats {
    /// Distinct tiles the frame wants.
    pub needed: usize,
    /// Tiles resident after the frame's uploads, wanted or not.
    pub resident: usize,
    /// Wanted tiles that are resident.
    pub needed_resident: usize,
    /// New loader requests this frame (the push list).
    pub requested: usize,
    /// Requested and not arrived yet.
    pub in_flight: usize,
    /// Arrived and waiting for a later frame's upload budget.
    pub staged: usize,
    /// Tiles written into slots this frame, within the upload budget.
    pub uploaded: usize,
    /// Resident tiles whose slot went to an arrival this frame.
    pub evicted: usize,
    /// Tiles found unusable this frame (each is counted once, ever).
    pub failed: usize,
    /// Bytes of this frame's uploads, all mips.
    pub bytes_uploaded: u64,
    /// Arrivals thrown away: no longer wanted, or no slot without evicting something more needed.
    pub dropped: usize,
}

/// How much one frame may upload to one cache. The first tile of a frame always goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UploadBudget {
    /// Most tiles uploaded in a frame (`cache.upload_tiles_per_frame`).
    pub tiles: usize,
    /// Most bytes uploaded in a frame (`cache.upload_bytes_per_frame`); a tile that would pass it
    /// waits for a later frame.
    pub bytes: u64,
}

impl UploadBudget {
    /// No limit: every arrived tile goes up at once (tools and tests).
    pub const UNLIMITED: Self = Self { tiles: usize::MAX, bytes: u64::MAX };
}

impl From<&CacheSettings> for UploadBudget {
    fn from(settings: &CacheSettings) -> Self {
        Self { tiles: settings.upload_tiles_per_frame as usize, bytes: settings.upload_bytes_per_frame }
    }
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    id: TileId,
    /// The last frame whose wanted list held this tile.
    last_needed_frame: u64,
}

/// A tile that became resident: where, and which tile it replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Placement {
    pub slot: u32,
    pub evicted: Option<TileId>,
}

pub struct Residency {
    layer: LayerKind,
    /// Levels of the layer's pyramid: where the walk to an ancestor stops.
    levels: u32,
    slots: Vec<Option<Slot>>,
    /// Slots never used or freed, popped from the end.
    free: Vec<u32>,
    resident: HashMap<TileId, u32>,
    failed: HashSet<TileId>,
    /// This frame's wants and their rank (first occurrence).
    needed: HashMap<TileId, u32>,
    /// Rank of the last fitting tile this frame (`None`: nothing fits, e.g. no wants).
    fit_rank: Option<u32>,
    in_flight: HashSet<TileId>,
    staged: HashMap<TileId, Arc<[u8]>>,
    frame: u64,
    stats: CacheStats,
}

impl Residency {
    pub fn new(layer: LayerKind, capacity: u32, levels: u32) -> Self {
        Self {
            layer,
            levels,
            slots: vec![None; capacity as usize],
            free: (0..capacity).rev().collect(),
            resident: HashMap::new(),
            failed: HashSet::new(),
            needed: HashMap::new(),
            fit_rank: None,
            in_flight: HashSet::new(),
            staged: HashMap::new(),
            frame: 0,
            stats: CacheStats::default(),
        }
    }

    pub fn layer(&self) -> LayerKind {
        self.layer
    }

    pub fn capacity(&self) -> usize {
        self.slots.len()
    }

    pub fn slot_of(&self, id: TileId) -> Option<u32> {
        self.resident.get(&id).copied()
    }

    pub fn is_failed(&self, id: TileId) -> bool {
        self.failed.contains(&id)
    }

    pub fn resident_tiles(&self) -> impl Iterator<Item = (TileId, u32)> + '_ {
        self.resident.iter().map(|(&id, &slot)| (id, slot))
    }

    /// The finest resident tile at or above `id`, with its slot.
    pub fn resident_ancestor(&self, id: TileId) -> Option<(TileId, u32)> {
        let mut tile = id;
        loop {
            if let Some(&slot) = self.resident.get(&tile) {
                return Some((tile, slot));
            }
            if tile.level + 1 >= self.levels {
                return None;
            }
            tile = TileId::new(tile.level + 1, tile.x / 2, tile.y / 2);
        }
    }

    /// Records this frame's wants (most important first) and returns the loader requests for
    /// the fitting tiles neither resident, arrived nor failed. Tiles already in flight are
    /// requested again with their new rank (the loader skips what it is reading); `requested`
    /// counts the new ones.
    pub fn set_wanted(&mut self, wanted: &[TileId], frame: u64) -> Vec<TileRequest> {
        self.frame = frame;
        self.stats = CacheStats::default();
        self.needed.clear();
        for (rank, &id) in wanted.iter().enumerate() {
            self.needed.entry(id).or_insert(rank as u32);
        }
        self.stats.needed = self.needed.len();
        for slot in self.slots.iter_mut().flatten() {
            if self.needed.contains_key(&slot.id) {
                slot.last_needed_frame = frame;
            }
        }
        self.fit_rank = None;
        let mut fitting = 0;
        let mut requests = Vec::new();
        for (rank, &id) in wanted.iter().enumerate() {
            if fitting == self.slots.len() {
                break;
            }
            let rank = rank as u32;
            if self.failed.contains(&id) || self.needed.get(&id) != Some(&rank) {
                continue; // failed, or a repeat of an earlier entry
            }
            fitting += 1;
            self.fit_rank = Some(rank);
            if self.resident.contains_key(&id) || self.staged.contains_key(&id) {
                continue;
            }
            if self.in_flight.insert(id) {
                self.stats.requested += 1;
            }
            requests.push(TileRequest { layer: self.layer, id, priority: rank });
        }
        let fit_rank = self.fit_rank;
        let needed = &self.needed;
        let fits = |id: &TileId| fit_rank.is_some_and(|f| needed.get(id).is_some_and(|&r| r <= f));
        self.in_flight.retain(fits);
        let staged_before = self.staged.len();
        self.staged.retain(|id, _| fits(id));
        self.stats.dropped += staged_before - self.staged.len();
        requests
    }

    fn fits(&self, id: TileId) -> bool {
        let rank = self.needed.get(&id);
        !self.failed.contains(&id) && self.fit_rank.is_some_and(|f| rank.is_some_and(|&r| r <= f))
    }

    /// Takes this layer's arrivals: errors mark their tile failed, fitting payloads of
    /// `tile_bytes` wait for upload, the rest are dropped.
    pub fn accept(&mut self, loaded: &[Loaded], tile_bytes: usize) {
        let layer = self.layer;
        for l in loaded.iter().filter(|l| l.layer == layer) {
            self.in_flight.remove(&l.id);
            match &l.result {
                Err(_) => self.fail(l.id),
                Ok(payload) if payload.len() != tile_bytes => {
                    eprintln!(
                        "terramp: {} tile {:?} is {} bytes, the cache expects {tile_bytes}; its ancestor stands in",
                        self.layer,
                        l.id,
                        payload.len()
                    );
                    self.fail(l.id);
                }
                Ok(payload) if self.fits(l.id) && !self.resident.contains_key(&l.id) => {
                    self.staged.insert(l.id, payload.clone());
                }
                Ok(_) => self.stats.dropped += 1,
            }
        }
    }

    /// Remembers a tile that cannot be read, for good.
    pub fn fail(&mut self, id: TileId) {
        self.in_flight.remove(&id);
        self.staged.remove(&id);
        if self.failed.insert(id) {
            self.stats.failed += 1;
        }
    }

    /// Arrived tiles, most important first.
    pub fn staged_in_order(&self) -> Vec<TileId> {
        let mut ids: Vec<(u32, TileId)> =
            self.staged.keys().map(|id| (self.needed.get(id).copied().unwrap_or(u32::MAX), *id)).collect();
        ids.sort_unstable();
        ids.into_iter().map(|(_, id)| id).collect()
    }

    /// The payload of arrived tile `id` if this frame's budget still allows it (the first upload
    /// of a frame always does). `None` when the budget is spent: the tile waits for a later frame.
    pub fn take_staged(&mut self, id: TileId, budget: UploadBudget) -> Option<Arc<[u8]>> {
        let bytes = self.staged.get(&id)?.len() as u64;
        let over = self.stats.uploaded >= budget.tiles || self.stats.bytes_uploaded + bytes > budget.bytes;
        if self.stats.uploaded > 0 && over {
            return None;
        }
        self.staged.remove(&id)
    }

    /// Makes `id` resident if a slot can be had without evicting anything more important, and
    /// counts a `bytes` upload; else counts it dropped.
    pub fn claim(&mut self, id: TileId, bytes: u64) -> Option<Placement> {
        self.in_flight.remove(&id);
        if let Some(&slot) = self.resident.get(&id) {
            return Some(Placement { slot, evicted: None });
        }
        let rank = self.needed.get(&id).copied().unwrap_or(u32::MAX);
        let Some(slot) = self.free.pop().or_else(|| self.victim(rank)) else {
            self.stats.dropped += 1;
            return None;
        };
        let evicted = self.slots[slot as usize].map(|old| old.id);
        if let Some(old) = evicted {
            self.resident.remove(&old);
            self.stats.evicted += 1;
        }
        self.slots[slot as usize] = Some(Slot { id, last_needed_frame: self.frame });
        self.resident.insert(id, slot);
        self.stats.uploaded += 1;
        self.stats.bytes_uploaded += bytes;
        Some(Placement { slot, evicted })
    }

    /// The slot to give a tile of rank `rank`: an unneeded tile (least recently needed, finer
    /// first), else the least important needed tile less important than it.
    fn victim(&self, rank: u32) -> Option<u32> {
        self.slots
            .iter()
            .enumerate()
            .filter_map(|(i, slot)| {
                let slot = slot.as_ref()?;
                let key = match self.needed.get(&slot.id) {
                    None => (0u8, slot.last_needed_frame, slot.id.level),
                    Some(&r) if r > rank => (1, u64::from(u32::MAX - r), 0),
                    Some(_) => return None,
                };
                Some((key, i as u32))
            })
            .min()
            .map(|(_, i)| i)
    }

    /// This frame's figures so far.
    pub fn stats(&self) -> CacheStats {
        let needed_resident = self.needed.keys().filter(|id| self.resident.contains_key(id)).count();
        CacheStats {
            resident: self.resident.len(),
            needed_resident,
            in_flight: self.in_flight.len(),
            staged: self.staged.len(),
            ..self.stats.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::streaming::loader::LoaderError;

    const BYTES: usize = 4;

    fn t(level: u32, x: u32) -> TileId {
        TileId::new(level, x, 0)
    }

    fn arrive(ids: &[TileId]) -> Vec<Loaded> {
        let ok = |id| Loaded { layer: LayerKind::Imagery, id, result: Ok(Arc::from(vec![0u8; BYTES])) };
        ids.iter().map(|&id| ok(id)).collect()
    }

    /// One frame: wants, arrivals, uploads within `budget`; returns the requests.
    fn frame(
        r: &mut Residency,
        wanted: &[TileId],
        n: u64,
        loaded: &[TileId],
        budget: UploadBudget,
    ) -> Vec<TileId> {
        let requests = r.set_wanted(wanted, n).into_iter().map(|q| q.id).collect();
        r.accept(&arrive(loaded), BYTES);
        for id in r.staged_in_order() {
            let Some(payload) = r.take_staged(id, budget) else { break };
            r.claim(id, payload.len() as u64);
        }
        requests
    }

    const ALL: UploadBudget = UploadBudget::UNLIMITED;

    #[test]
    fn requests_only_what_fits_and_is_not_there_or_coming() {
        let mut r = Residency::new(LayerKind::Imagery, 2, 3);
        let wanted = [t(2, 0), t(1, 0), t(0, 0)];
        assert_eq!(frame(&mut r, &wanted, 0, &[], ALL), [t(2, 0), t(1, 0)]);
        assert_eq!(r.stats().requested, 2);
        // Re-sent with their rank, but not new.
        assert_eq!(frame(&mut r, &wanted, 1, &[t(2, 0)], ALL), [t(2, 0), t(1, 0)]);
        assert_eq!((r.stats().requested, r.stats().uploaded, r.stats().in_flight), (0, 1, 1));
        assert_eq!(frame(&mut r, &wanted, 2, &[], ALL), [t(1, 0)]);
    }

    #[test]
    fn budget_is_kept_but_one_tile_always_goes() {
        let mut r = Residency::new(LayerKind::Imagery, 8, 3);
        let wanted: Vec<TileId> = (0..6).map(|x| t(0, x)).collect();
        frame(&mut r, &wanted, 0, &[], ALL);
        let tiny = UploadBudget { tiles: 2, bytes: 1 };
        frame(&mut r, &wanted, 1, &wanted, tiny);
        assert_eq!((r.stats().uploaded, r.stats().staged), (1, 5));
        let two = UploadBudget { tiles: 2, bytes: 100 };
        frame(&mut r, &wanted, 2, &[], two);
        assert_eq!((r.stats().uploaded, r.stats().staged), (2, 3));
        // Arrived tiles are uploaded most important first, never requested again.
        assert!(r.slot_of(t(0, 0)).is_some() && r.slot_of(t(0, 2)).is_some() && r.slot_of(t(0, 3)).is_none());
        assert_eq!(frame(&mut r, &wanted, 3, &[], two), Vec::<TileId>::new());
    }

    #[test]
    fn evicts_least_recently_needed_never_needed_for_less_needed() {
        let mut r = Residency::new(LayerKind::Imagery, 3, 3);
        let (a, b, c, d) = (t(1, 0), t(0, 1), t(0, 2), t(0, 3));
        frame(&mut r, &[a, b, c], 0, &[a, b, c], ALL);
        frame(&mut r, &[a, c], 1, &[], ALL);
        frame(&mut r, &[a], 2, &[], ALL);
        // b (unneeded since frame 0) goes before c (unneeded since frame 1).
        frame(&mut r, &[a, d], 3, &[d], ALL);
        assert_eq!(r.slot_of(b), None);
        assert!(r.slot_of(c).is_some() && r.slot_of(d).is_some());
        // All three needed: a late, less important arrival cannot push out a more important one.
        let e = t(0, 4);
        r.set_wanted(&[a, c, d, e], 4);
        assert_eq!(r.claim(e, 4), None);
        assert_eq!(r.stats().dropped, 1);
        // A more important one may push out the least important needed tile.
        r.set_wanted(&[e, a, c, d], 5);
        assert_eq!(r.claim(e, 4).and_then(|p| p.evicted), Some(d));
    }

    #[test]
    fn failed_tiles_are_remembered_and_their_ancestor_stands_in() {
        let mut r = Residency::new(LayerKind::Imagery, 4, 3);
        let (root, mid, leaf) = (t(2, 0), TileId::new(1, 1, 1), TileId::new(0, 3, 2));
        frame(&mut r, &[root, mid, leaf], 0, &[root], ALL);
        let error = Loaded {
            layer: LayerKind::Imagery,
            id: mid,
            result: Err(LoaderError::NoLayer(LayerKind::Imagery)),
        };
        r.accept(&[error], BYTES);
        assert_eq!(r.stats().failed, 1);
        assert!(r.is_failed(mid));
        assert_eq!(frame(&mut r, &[root, mid, leaf], 1, &[], ALL), [leaf]);
        assert_eq!(r.resident_ancestor(leaf).map(|(id, _)| id), Some(root));
        assert_eq!(r.resident_ancestor(TileId::new(5, 0, 0)), None);
    }

    #[test]
    fn arrivals_no_longer_wanted_are_dropped() {
        let mut r = Residency::new(LayerKind::Imagery, 4, 3);
        frame(&mut r, &[t(0, 0), t(0, 1)], 0, &[], ALL);
        frame(&mut r, &[t(0, 1)], 1, &[t(0, 0), t(0, 1)], ALL);
        assert_eq!((r.stats().dropped, r.stats().uploaded), (1, 1));
        assert_eq!(r.slot_of(t(0, 0)), None);
        // Other layers' arrivals are not this cache's business.
        let mut other = arrive(&[t(0, 2)]);
        other[0].layer = LayerKind::Height;
        r.accept(&other, BYTES);
        assert_eq!(r.stats().dropped, 1);
    }
}
