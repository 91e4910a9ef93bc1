//! How it works: a fixed-size texture-array cache of one layer's tiles, addressed through a page
//! table. GPU memory is fixed at creation by the slot count; nothing grows with the dataset.
//!
//! The page table is a storage buffer with one `u32` per tile of the layer's pyramid, in the
//! pyramid's own tile order (so a shader finds a tile's entry in O(1) from its level, x and y): 0
//! when the tile is not resident, else its slot + 1. `update` takes the tiles a frame wants, most
//! important first, makes as many resident as there are slots, evicting the least recently wanted
//! tiles first, and never evicts a tile the frame wants to make room for a less important one. A
//! tile that cannot be read (missing, corrupt) is reported once and remembered as failed: shaders
//! fall back to its ancestor.

use std::collections::{HashMap, HashSet};

use crate::dataset::{PackError, Pyramid, TileId};

/// What one `update` did.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct CacheStats {
    pub wanted: usize,
    pub resident: usize,
    pub uploaded: usize,
    pub evicted: usize,
    pub failed: usize,
    pub bytes_uploaded: u64,
}

pub struct TileCache {
    label: &'static str,
    pyramid: Pyramid,
    mips: u32,
    texel_bytes: u32,
    format: wgpu::TextureFormat,
    texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    pub page_table: wgpu::Buffer,
    page_table_cpu: Vec<u32>,
    /// Per slot: the tile it holds and the last frame that wanted it.
    slots: Vec<Option<(TileId, u64)>>,
    resident: HashMap<TileId, u32>,
    failed: HashSet<TileId>,
}

impl TileCache {
    pub fn new(
        device: &wgpu::Device,
        label: &'static str,
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
        let page_table_cpu = vec![0u32; pyramid.tile_count() as usize];
        let page_table = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (page_table_cpu.len().max(1) * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let texel_bytes = format.block_copy_size(None).unwrap_or(4);
        Self {
            label,
            pyramid,
            mips,
            texel_bytes,
            format,
            texture,
            view,
            page_table,
            page_table_cpu,
            slots: vec![None; slots as usize],
            resident: HashMap::new(),
            failed: HashSet::new(),
        }
    }

    pub fn slot_of(&self, id: TileId) -> Option<u32> {
        self.resident.get(&id).copied()
    }

    pub fn capacity(&self) -> usize {
        self.slots.len()
    }

    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Makes the `wanted` tiles (most important first) resident as far as the slots allow.
    /// `read` returns a tile's payload (all mips), checksum verified.
    pub fn update<'a>(
        &mut self,
        queue: &wgpu::Queue,
        wanted: &[TileId],
        frame: u64,
        mut read: impl FnMut(TileId) -> Result<&'a [u8], PackError>,
    ) -> CacheStats {
        let mut stats = CacheStats { wanted: wanted.len(), ..Default::default() };
        let keep: Vec<TileId> =
            wanted.iter().copied().filter(|id| !self.failed.contains(id)).take(self.slots.len()).collect();
        for id in &keep {
            if let Some(&slot) = self.resident.get(id) {
                self.slots[slot as usize] = Some((*id, frame));
            }
        }
        let mut table_changed = false;
        for &id in &keep {
            if self.resident.contains_key(&id) {
                continue;
            }
            let payload = match read(id) {
                Ok(payload) => payload,
                Err(error) => {
                    eprintln!(
                        "terramp: {} tile {id:?} unusable, its ancestor stands in: {error}",
                        self.label
                    );
                    self.failed.insert(id);
                    stats.failed += 1;
                    continue;
                }
            };
            // Free slots first, then the least recently wanted tile this frame does not want.
            let Some(slot) = self.victim(frame) else { break };
            if let Some((old, _)) = self.slots[slot].take() {
                self.resident.remove(&old);
                self.set_entry(old, 0);
                stats.evicted += 1;
            }
            self.upload(queue, slot as u32, payload);
            self.slots[slot] = Some((id, frame));
            self.resident.insert(id, slot as u32);
            self.set_entry(id, slot as u32 + 1);
            table_changed = true;
            stats.uploaded += 1;
            stats.bytes_uploaded += payload.len() as u64;
        }
        if table_changed || stats.evicted > 0 {
            queue.write_buffer(&self.page_table, 0, bytemuck::cast_slice(&self.page_table_cpu));
        }
        stats.resident = self.resident.len();
        stats
    }

    fn victim(&self, frame: u64) -> Option<usize> {
        if let Some(free) = self.slots.iter().position(Option::is_none) {
            return Some(free);
        }
        self.slots
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.map(|(_, used)| (i, used)))
            .filter(|&(_, used)| used != frame)
            .min_by_key(|&(_, used)| used)
            .map(|(i, _)| i)
    }

    fn set_entry(&mut self, id: TileId, value: u32) {
        if let Some(index) = self.pyramid.tile_index(id) {
            self.page_table_cpu[index as usize] = value;
        }
    }

    fn upload(&self, queue: &wgpu::Queue, slot: u32, payload: &[u8]) {
        let mut offset = 0usize;
        for mip in 0..self.mips {
            let extent = self.pyramid.mip_extent(mip);
            let bytes = (extent * extent * self.texel_bytes) as usize;
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: mip,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: slot },
                    aspect: wgpu::TextureAspect::All,
                },
                &payload[offset..offset + bytes],
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(extent * self.texel_bytes),
                    rows_per_image: Some(extent),
                },
                wgpu::Extent3d { width: extent, height: extent, depth_or_array_layers: 1 },
            );
            offset += bytes;
        }
    }
}
