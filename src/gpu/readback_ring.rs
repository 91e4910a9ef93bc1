//! How it works: reading a GPU buffer back without stalling the frame. The ring owns a few
//! mappable staging buffers. Each frame, `encode_copy` records a copy of the source into the next
//! free one, with the caller's tag (the frame's index and whatever the caller needs to read the
//! bytes: a layout, a camera); after the frame's submit, `submitted` asks wgpu to map it.
//! `try_take` polls the device without waiting and hands back the oldest copy whose buffer has
//! mapped, as owned bytes with their tag, and frees its buffer. Results come in the order they
//! were recorded, one or two frames late, so a caller keeps no queue of its own. When every buffer
//! is still in flight (the GPU is that far behind), the frame's copy is skipped and counted: a
//! late CPU reader loses a frame, never the frame rate. The ring counts the bytes it copied, for
//! the frame's counts (`gpu::counts`).

use std::collections::VecDeque;
use std::sync::{Arc, OnceLock};

use super::GpuError;

/// Staging buffers the TLM readback rotates through: one being written by the GPU, one mapping,
/// one being read on the CPU.
pub const DEFAULT_SLOTS: usize = 3;

/// One copy's bytes, read back, with the tag it was recorded with.
#[derive(Debug, Clone, PartialEq)]
pub struct Readback<Tag> {
    /// What the caller gave `encode_copy` with this copy.
    pub tag: Tag,
    /// The copied bytes, as many as `encode_copy` was asked for.
    pub bytes: Vec<u8>,
}

impl<Tag> Readback<Tag> {
    /// The bytes as `T`s (a copy; the byte count must be a multiple of `T`'s size).
    pub fn cast<T: bytemuck::Pod>(&self) -> Vec<T> {
        bytemuck::pod_collect_to_vec(&self.bytes)
    }
}

type MapStatus = Arc<OnceLock<Result<(), wgpu::BufferAsyncError>>>;

/// A staging buffer's state; a copy's tag travels with it until `try_take` hands it back.
enum Slot<Tag> {
    Free,
    /// A copy is recorded but its encoder is not known to be submitted yet.
    Recorded {
        bytes: u64,
        tag: Tag,
    },
    Mapping {
        bytes: u64,
        status: MapStatus,
        tag: Tag,
    },
}

/// A ring of staging buffers whose copies carry a `Tag`.
pub struct ReadbackRing<Tag> {
    buffers: Vec<wgpu::Buffer>,
    slots: Vec<Slot<Tag>>,
    /// Slots holding a frame, oldest first.
    order: VecDeque<usize>,
    capacity_bytes: u64,
    skipped: u64,
    /// Bytes of every copy recorded so far.
    copied_bytes: u64,
}

impl<Tag> ReadbackRing<Tag> {
    /// `slots` staging buffers of `capacity_bytes` each.
    pub fn new(device: &wgpu::Device, label: &str, capacity_bytes: u64, slots: usize) -> Self {
        let capacity_bytes = capacity_bytes.next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
        let buffers = (0..slots.max(1))
            .map(|i| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("{label} readback {i}")),
                    size: capacity_bytes,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                })
            })
            .collect::<Vec<_>>();
        let slots = buffers.iter().map(|_| Slot::Free).collect();
        Self { buffers, slots, order: VecDeque::new(), capacity_bytes, skipped: 0, copied_bytes: 0 }
    }

    /// Records a copy of the first `bytes` of `source`, tagged `tag`, into a free staging
    /// buffer. False (and counted) when none is free or `bytes` exceeds the capacity; the copy
    /// is then simply not made.
    pub fn encode_copy(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        bytes: u64,
        tag: Tag,
    ) -> bool {
        let free = self.slots.iter().position(|s| matches!(s, Slot::Free));
        let (Some(index), true) = (free, bytes <= self.capacity_bytes && bytes.is_multiple_of(4)) else {
            self.skipped += 1;
            return false;
        };
        if bytes > 0 {
            encoder.copy_buffer_to_buffer(source, 0, &self.buffers[index], 0, bytes);
        }
        self.copied_bytes += bytes;
        self.slots[index] = Slot::Recorded { bytes, tag };
        self.order.push_back(index);
        true
    }

    /// Call after submitting the encoder(s) holding the copies: starts mapping them.
    pub fn submitted(&mut self) {
        for (slot, buffer) in self.slots.iter_mut().zip(&self.buffers) {
            if let Slot::Recorded { .. } = slot {
                let Slot::Recorded { bytes, tag } = std::mem::replace(slot, Slot::Free) else { continue };
                let status: MapStatus = Arc::default();
                let sink = Arc::clone(&status);
                if bytes > 0 {
                    buffer.slice(..bytes).map_async(wgpu::MapMode::Read, move |result| {
                        let _ = sink.set(result);
                    });
                } else {
                    let _ = sink.set(Ok(()));
                }
                *slot = Slot::Mapping { bytes, status, tag };
            }
        }
    }

    /// The oldest copy, if it has arrived; never waits for the GPU.
    pub fn try_take(&mut self, device: &wgpu::Device) -> Result<Option<Readback<Tag>>, GpuError> {
        device.poll(wgpu::PollType::Poll)?;
        let Some(&index) = self.order.front() else { return Ok(None) };
        let Slot::Mapping { status, .. } = &self.slots[index] else { return Ok(None) };
        let Some(result) = status.get().cloned() else { return Ok(None) };
        self.order.pop_front();
        let Slot::Mapping { bytes, tag, .. } = std::mem::replace(&mut self.slots[index], Slot::Free) else {
            return Ok(None);
        };
        result?;
        if bytes == 0 {
            return Ok(Some(Readback { tag, bytes: Vec::new() }));
        }
        let buffer = &self.buffers[index];
        let copy = {
            let mapped =
                buffer.slice(..bytes).get_mapped_range().map_err(|e| GpuError::Validation(e.to_string()))?;
            mapped.to_vec()
        };
        buffer.unmap();
        Ok(Some(Readback { tag, bytes: copy }))
    }

    /// Copies skipped because no staging buffer was free (or they did not fit).
    pub fn skipped(&self) -> u64 {
        self.skipped
    }

    /// Bytes of every copy recorded so far (skipped ones are not): what this ring read back.
    pub fn copied_bytes(&self) -> u64 {
        self.copied_bytes
    }

    /// Copies recorded and not yet taken.
    pub fn in_flight(&self) -> usize {
        self.order.len()
    }

    /// Size of each staging buffer, bytes (as asked, rounded up to wgpu's copy alignment): the
    /// largest copy `encode_copy` accepts.
    pub fn capacity_bytes(&self) -> u64 {
        self.capacity_bytes
    }
}
