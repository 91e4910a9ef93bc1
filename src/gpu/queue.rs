//! How it works: the device's queue, counting the bytes it uploads and the bytes read back through
//! it, for `gpu::counts`. It dereferences to wgpu's queue, so submitting and everything else is
//! wgpu's own; only `write_buffer` and `write_texture` are its own, and they count the bytes they
//! hand wgpu before handing them on. A frame's uploads are the difference between two readings
//! (`uploaded_bytes`) around its CPU steps. Clones share the counts, as they share the queue: a
//! renderer remade on the same device counts on. Readbacks cannot be seen from the queue (they
//! are copies inside encoders), so the blocking readers (`gpu::readback`) say what they read with
//! `note_read_back`, and the frame's staging rings count their own copies
//! (`ReadbackRing::copied_bytes`).

use std::ops::Deref;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// What crossed between the CPU and the GPU through one queue, since it was opened.
#[derive(Debug, Default)]
struct Traffic {
    uploaded_bytes: AtomicU64,
    read_back_bytes: AtomicU64,
}

/// wgpu's queue, with its uploads and readbacks counted.
#[derive(Debug, Clone)]
pub struct Queue {
    queue: wgpu::Queue,
    traffic: Arc<Traffic>,
}

impl Deref for Queue {
    type Target = wgpu::Queue;

    fn deref(&self) -> &wgpu::Queue {
        &self.queue
    }
}

impl Queue {
    /// Counts what goes through `queue` from now on.
    pub fn new(queue: wgpu::Queue) -> Self {
        Self { queue, traffic: Arc::default() }
    }

    /// `wgpu::Queue::write_buffer`, counted: `data.len()` bytes.
    pub fn write_buffer(&self, buffer: &wgpu::Buffer, offset: wgpu::BufferAddress, data: &[u8]) {
        self.traffic.uploaded_bytes.fetch_add(data.len() as u64, Ordering::Relaxed);
        self.queue.write_buffer(buffer, offset, data);
    }

    /// `wgpu::Queue::write_texture`, counted: `data.len()` bytes (every caller hands it exactly
    /// the texels it copies).
    pub fn write_texture(
        &self,
        texture: wgpu::TexelCopyTextureInfo,
        data: &[u8],
        layout: wgpu::TexelCopyBufferLayout,
        size: wgpu::Extent3d,
    ) {
        self.traffic.uploaded_bytes.fetch_add(data.len() as u64, Ordering::Relaxed);
        self.queue.write_texture(texture, data, layout, size);
    }

    /// Bytes uploaded through this queue (and its clones) so far.
    pub fn uploaded_bytes(&self) -> u64 {
        self.traffic.uploaded_bytes.load(Ordering::Relaxed)
    }

    /// Counts `bytes` a blocking reader copied into mappable memory and read.
    pub fn note_read_back(&self, bytes: u64) {
        self.traffic.read_back_bytes.fetch_add(bytes, Ordering::Relaxed);
    }

    /// Bytes the blocking readers read back so far (`note_read_back`).
    pub fn read_back_bytes(&self) -> u64 {
        self.traffic.read_back_bytes.load(Ordering::Relaxed)
    }
}
