//! How it works: one module per GPU pass of the frame after the terrain, each with its shader of
//! the same name in `shaders/` and, for the passes whose output the CPU relies on, a CPU twin of
//! the same name in `reference/`. A pass builds its pipelines once in `new`, writes its per-frame
//! inputs in `prepare`, and only records commands in `encode`; `frame.rs` calls them in order.

pub mod compact;
pub mod depth_pyramid;
pub mod draw_seeds;
pub mod ground;
pub mod seed_select;
pub mod tile_load_map;

use crate::gpu::readback_ring::ReadbackRing;
use crate::gpu::{Gpu, GpuError};

/// The first `bytes` of `buffer` (a `COPY_SRC` buffer), waiting for the GPU: for tests and tools,
/// never the frame.
pub(crate) fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, GpuError> {
    let mut ring = ReadbackRing::new(&gpu.device, "blocking readback", bytes.max(4), 1);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    ring.encode_copy(&mut encoder, buffer, bytes.next_multiple_of(4), 0);
    gpu.queue.submit([encoder.finish()]);
    ring.submitted();
    gpu.wait()?;
    let taken = ring.try_take(&gpu.device)?;
    gpu.check()?;
    let mut bytes_read = taken
        .map(|r| r.bytes)
        .ok_or_else(|| GpuError::Validation("a blocking readback did not arrive after a wait".into()))?;
    bytes_read.truncate(bytes as usize);
    Ok(bytes_read)
}
