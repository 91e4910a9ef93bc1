//! How it works: a fixed-size texture-array cache of one layer's tiles, addressed through a page
//! table. GPU memory is fixed at creation by the slot count; nothing grows with the dataset.
//!
//! The page table is a storage buffer with one `u32` per tile of the layer's pyramid, in the
//! pyramid's own tile order (so a shader finds a tile's entry in O(1) from its level, x and y, at
//! `page_levels`): `PAGE_EMPTY` when the tile is not resident, else `page_entry(slot)`. Only the
//! entries that changed are written.
//!
//! The render thread drives it once a frame: `set_wanted` records what the frame needs (most
//! important first) and returns the loader requests; `upload` takes what the loader read and
//! uploads it, most important first, within the frame's upload budget. Which tile goes where, and
//! what is evicted, is `Residency`'s policy (least recently needed first, never a needed tile for a
//! less important one). `load_now` is the synchronous path for tools and tests: it reads every
//! fitting tile at once, with no budget. A tile that cannot be read is remembered as failed, and
//! shaders (and `resident_ancestor`) fall back to its finest resident ancestor. A cache may keep a
//! few words beside each slot (`with_summary`: the height cache, its tile's block tops for pass 3),
//! made from the tile as it is placed.

use super::LayerKind;
use super::loader::Loaded;
use super::residency::{CacheStats, Placement, Residency, UploadBudget};
use crate::dataset::{MipLayout, PackError, Pyramid, TileId};
use crate::gpu::layout::{PAGE_EMPTY, page_entry};

/// One layer's GPU tile cache: a texture array with a tile in each of its fixed number of slots,
/// the page table that maps the layer's tiles to slots, and the policy that fills them.
pub struct TileCache {
    label: &'static str,
    pyramid: Pyramid,
    mips: u32,
    format: wgpu::TextureFormat,
    texture: wgpu::Texture,
    /// A 2D-array view of every slot, all mips: what the passes bind to read tiles.
    pub view: wgpu::TextureView,
    /// The page table as a storage buffer: one `u32` per tile of the pyramid.
    pub page_table: wgpu::Buffer,
    page_table_cpu: Vec<u32>,
    /// Page-table entries changed since the last write to the GPU.
    dirty: Vec<u32>,
    residency: Residency,
    /// What it keeps beside each slot's tile, and where (`with_summary`).
    summary: Option<(SlotSummary, wgpu::Buffer)>,
}

/// What a cache keeps beside each slot's tile, `words_per_slot` words per slot in a storage buffer
/// (slot `s` at word `s × words_per_slot`): made from the tile's payload (all mips) when it is
/// placed, in the same queue order as its texels and before its page-table entry, so a pass that
/// finds the tile through the page table finds its summary too.
#[derive(Clone, Copy)]
pub struct SlotSummary {
    /// The buffer's label.
    pub label: &'static str,
    /// Words kept per slot.
    pub words_per_slot: u32,
    /// The summary of a tile from its payload: `words_per_slot` words.
    pub make: fn(&[u8]) -> Vec<u32>,
}

impl TileCache {
    /// An empty cache of `slots` tiles of `layer`, each `pyramid.tile_extent()` texels square with
    /// `mips` mips of `format`; every page-table entry starts `PAGE_EMPTY`.
    pub fn new(
        device: &wgpu::Device,
        label: &'static str,
        layer: LayerKind,
        pyramid: Pyramid,
        mips: u32,
        format: wgpu::TextureFormat,
        slots: u32,
    ) -> Self {
        let extent = pyramid.tile_extent();
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: extent, height: extent, depth_or_array_layers: slots },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let page_table_cpu = vec![PAGE_EMPTY; pyramid.tile_count() as usize];
        let page_table = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (page_table_cpu.len().max(1) * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            // Zeroed by wgpu: every tile starts absent.
            mapped_at_creation: false,
        });
        Self {
            label,
            pyramid,
            mips,
            format,
            texture,
            view,
            page_table,
            page_table_cpu,
            dirty: Vec::new(),
            residency: Residency::new(layer, slots, pyramid.levels),
            summary: None,
        }
    }

    /// The cache keeping `summary` beside each slot's tile from now on (call before placing any).
    pub fn with_summary(mut self, device: &wgpu::Device, summary: SlotSummary) -> Self {
        let slots = u64::from(self.slot_count());
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(summary.label),
            size: (slots * u64::from(summary.words_per_slot) * 4).max(4),
            // Read back by tests.
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        self.summary = Some((summary, buffer));
        self
    }

    /// The slots' summaries (`SlotSummary`), when the cache keeps any.
    pub fn summary_buffer(&self) -> Option<&wgpu::Buffer> {
        self.summary.as_ref().map(|(_, buffer)| buffer)
    }

    /// Slots in the cache: layers of its texture array.
    pub fn slot_count(&self) -> u32 {
        self.texture.depth_or_array_layers()
    }

    /// The page table as last written to the GPU (`page_entry(slot)` per tile, `PAGE_EMPTY` when
    /// absent): for CPU twins of the passes that read it.
    pub fn page_table_entries(&self) -> &[u32] {
        &self.page_table_cpu
    }

    /// The slot (texture-array layer) holding `id`; `None` while it is not resident.
    pub fn slot_of(&self, id: TileId) -> Option<u32> {
        self.residency.slot_of(id)
    }

    /// The finest resident tile at or above `id`, and its slot: what to draw while `id` streams
    /// in (or for good, if it failed).
    pub fn resident_ancestor(&self, id: TileId) -> Option<(TileId, u32)> {
        self.residency.resident_ancestor(id)
    }

    /// Every resident tile with its slot, in no particular order.
    pub fn resident_tiles(&self) -> impl Iterator<Item = (TileId, u32)> + '_ {
        self.residency.resident_tiles()
    }

    /// The tile could not be read (missing, corrupt) and will never be requested again.
    pub fn is_failed(&self, id: TileId) -> bool {
        self.residency.is_failed(id)
    }

    /// Slots in the cache: the most tiles resident at once.
    pub fn capacity(&self) -> usize {
        self.residency.capacity()
    }

    /// The dataset layer whose tiles the cache holds.
    pub fn layer(&self) -> LayerKind {
        self.residency.layer()
    }

    /// Texel format of the texture array, as the layer's packs store texels.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// The layer's tile quadtree, whose tile order the page table follows.
    pub fn pyramid(&self) -> &Pyramid {
        &self.pyramid
    }

    /// This frame's figures so far.
    pub fn stats(&self) -> CacheStats {
        self.residency.stats()
    }

    /// Bytes of one tile, all mips (in whole blocks for a block-compressed format): what the
    /// loader must deliver, and what a slot holds on the GPU.
    pub fn tile_bytes(&self) -> usize {
        (0..self.mips).map(|mip| self.mip_layout(mip).bytes()).sum()
    }

    fn mip_layout(&self, mip: u32) -> MipLayout {
        MipLayout::of(self.format, self.pyramid.mip_extent(mip))
    }

    /// Starts a frame: records the tiles it needs (most important first: coarse levels first,
    /// then nearest) and returns the requests to hand the loader (with every other cache's, in
    /// one `Loader::submit`). A frame runs:
    ///
    /// ```text
    /// let mut requests = heights.set_wanted(&wanted_heights, frame);
    /// requests.extend(imagery.set_wanted(&wanted_imagery, frame));
    /// loader.submit(&requests);              // every frame, even when empty: it cancels
    /// let loaded = loader.try_recv_all();    // never waits
    /// let height_stats = heights.upload(queue, &loaded, budget);
    /// let imagery_stats = imagery.upload(queue, &loaded, budget);
    /// ```
    pub fn set_wanted(&mut self, wanted: &[TileId], frame: u64) -> Vec<super::TileRequest> {
        self.residency.set_wanted(wanted, frame)
    }

    /// Takes the loader's results (other layers' are ignored) and uploads arrived tiles, most
    /// important first, within `budget`; the rest wait for later frames. Returns the frame's
    /// figures. Call after `set_wanted`, once a frame.
    pub fn upload(
        &mut self,
        queue: &crate::gpu::Queue,
        loaded: &[Loaded],
        budget: UploadBudget,
    ) -> CacheStats {
        self.residency.accept(loaded, self.tile_bytes());
        for id in self.residency.staged_in_order() {
            let Some(payload) = self.residency.take_staged(id, budget) else { break };
            self.place(queue, id, &payload);
        }
        self.flush_page_table(queue);
        self.stats()
    }

    /// Makes the `wanted` tiles (most important first) resident now, as far as the slots allow,
    /// with no budget. `read` returns a tile's payload (all mips), checksum verified.
    pub fn load_now<B: std::ops::Deref<Target = [u8]>>(
        &mut self,
        queue: &crate::gpu::Queue,
        wanted: &[TileId],
        frame: u64,
        mut read: impl FnMut(TileId) -> Result<B, PackError>,
    ) -> CacheStats {
        let tile_bytes = self.tile_bytes();
        for request in self.residency.set_wanted(wanted, frame) {
            match read(request.id) {
                Ok(payload) if payload.len() == tile_bytes => self.place(queue, request.id, &payload),
                Ok(payload) => {
                    let id = request.id;
                    eprintln!(
                        "terramp: {} tile {id:?} is {} bytes, the cache expects {tile_bytes}; its ancestor stands in",
                        self.label,
                        payload.len()
                    );
                    self.residency.fail(id);
                }
                Err(error) => {
                    eprintln!(
                        "terramp: {} tile {:?} unusable, its ancestor stands in: {error}",
                        self.label, request.id
                    );
                    self.residency.fail(request.id);
                }
            }
        }
        self.flush_page_table(queue);
        self.stats()
    }

    fn place(&mut self, queue: &crate::gpu::Queue, id: TileId, payload: &[u8]) {
        let Some(Placement { slot, evicted }) = self.residency.claim(id, payload.len() as u64) else {
            return;
        };
        if let Some(old) = evicted {
            self.set_entry(old, PAGE_EMPTY);
        }
        self.write_tile(queue, slot, payload);
        if let Some((summary, buffer)) = &self.summary {
            let words = (summary.make)(payload);
            debug_assert_eq!(words.len(), summary.words_per_slot as usize, "{}", summary.label);
            let offset = u64::from(slot) * u64::from(summary.words_per_slot) * 4;
            queue.write_buffer(buffer, offset, bytemuck::cast_slice(&words));
        }
        self.set_entry(id, page_entry(slot));
    }

    fn set_entry(&mut self, id: TileId, value: u32) {
        if let Some(index) = self.pyramid.tile_index(id) {
            self.page_table_cpu[index as usize] = value;
            self.dirty.push(index as u32);
        }
    }

    /// Writes the changed page-table entries, one write per run of neighbouring entries: a few
    /// dozen bytes a frame, however large the pyramid.
    fn flush_page_table(&mut self, queue: &crate::gpu::Queue) {
        self.dirty.sort_unstable();
        self.dirty.dedup();
        let mut runs = self.dirty.chunk_by(|a, b| a + 1 == *b);
        for run in &mut runs {
            let (first, last) = (run[0] as usize, run[run.len() - 1] as usize);
            let bytes: &[u8] = bytemuck::cast_slice(&self.page_table_cpu[first..=last]);
            queue.write_buffer(&self.page_table, (first * 4) as u64, bytes);
        }
        self.dirty.clear();
    }

    fn write_tile(&self, queue: &crate::gpu::Queue, slot: u32, payload: &[u8]) {
        let mut offset = 0usize;
        for mip in 0..self.mips {
            let layout = self.mip_layout(mip);
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: mip,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: slot },
                    aspect: wgpu::TextureAspect::All,
                },
                &payload[offset..offset + layout.bytes()],
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(layout.bytes_per_row),
                    rows_per_image: Some(layout.blocks_y),
                },
                // Whole blocks: a mip of 66 texels is copied as the 68 its blocks cover.
                wgpu::Extent3d {
                    width: layout.copy_extent,
                    height: layout.copy_extent,
                    depth_or_array_layers: 1,
                },
            );
            offset += layout.bytes();
        }
    }
}

/// Page-table addressing of `pyramid`'s levels as the shaders read it: per level its first entry,
/// tiles along x and tiles along y, then 0 (levels beyond `N` are left out).
pub fn page_levels<const N: usize>(pyramid: &Pyramid) -> [[u32; 4]; N] {
    let mut table = [[0; 4]; N];
    for level in 0..pyramid.levels.min(N as u32) {
        let [nx, ny] = pyramid.tiles_at(level);
        let first = pyramid.tile_index(TileId::new(level, 0, 0)).unwrap_or_default() as u32;
        table[level as usize] = [first, nx, ny, 0];
    }
    table
}
