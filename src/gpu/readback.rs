//! How it works: blocking readbacks, for frames written to disk, tools and tests; the per-frame
//! data paths never read back synchronously (they use `readback_ring`). A texture is copied into a
//! mappable buffer (rows padded to wgpu's 256-byte copy alignment) and returned tightly packed; a
//! buffer goes through a one-slot `ReadbackRing`, waited for. Each tells the queue the bytes it
//! copied (`Queue::note_read_back`: a texture's padded rows included).

use super::readback_ring::ReadbackRing;
use super::{Gpu, GpuError};

/// The first `bytes` of `buffer` (a `COPY_SRC` buffer), waiting for the GPU.
pub fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer, bytes: u64) -> Result<Vec<u8>, GpuError> {
    let mut ring = ReadbackRing::new(&gpu.device, "blocking readback", bytes.max(4), 1);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    ring.encode_copy(&mut encoder, buffer, bytes.next_multiple_of(4), ());
    gpu.queue.submit([encoder.finish()]);
    gpu.queue.note_read_back(ring.copied_bytes());
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

/// The first `count` values of type `T` in `buffer`, waiting for the GPU.
pub fn read_values<T: bytemuck::Pod>(
    gpu: &Gpu,
    buffer: &wgpu::Buffer,
    count: u64,
) -> Result<Vec<T>, GpuError> {
    let bytes = read_buffer(gpu, buffer, count * size_of::<T>() as u64)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}

/// The texels of mip 0 of `texture` (a 2D colour or depth texture), top row first,
/// `texel_bytes` per texel.
pub fn read_texture(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
    texel_bytes: u32,
) -> Result<Vec<u8>, GpuError> {
    read_texture_mip(gpu, texture, 0, aspect, texel_bytes)
}

/// The texels of every depth slice of 3D `texture`, slice by slice, each top row first.
pub fn read_texture_slices(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    texel_bytes: u32,
) -> Result<Vec<u8>, GpuError> {
    let mut texels = Vec::new();
    for slice in 0..texture.depth_or_array_layers() {
        texels.extend(read_texture_at(gpu, texture, 0, slice, wgpu::TextureAspect::All, texel_bytes)?);
    }
    Ok(texels)
}

/// The texels of mip `mip` of `texture`, top row first, `texel_bytes` per texel.
pub fn read_texture_mip(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    mip: u32,
    aspect: wgpu::TextureAspect,
    texel_bytes: u32,
) -> Result<Vec<u8>, GpuError> {
    read_texture_at(gpu, texture, mip, 0, aspect, texel_bytes)
}

/// The texels of mip `mip`, depth slice `slice` of `texture`.
fn read_texture_at(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    mip: u32,
    slice: u32,
    aspect: wgpu::TextureAspect,
    texel_bytes: u32,
) -> Result<Vec<u8>, GpuError> {
    let (width, height) = ((texture.width() >> mip).max(1), (texture.height() >> mip).max(1));
    let row_bytes = width * texel_bytes;
    let padded = row_bytes.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(padded) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: mip,
            origin: wgpu::Origin3d { x: 0, y: 0, z: slice },
            aspect,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    gpu.queue.note_read_back(buffer.size());
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    gpu.wait()?;
    receiver.recv().map_err(|_| GpuError::Validation("readback callback never ran".into()))??;
    let mapped = slice.get_mapped_range().map_err(|e| GpuError::Validation(e.to_string()))?;
    let mut texels = Vec::with_capacity((row_bytes * height) as usize);
    for row in mapped.chunks_exact(padded as usize) {
        texels.extend_from_slice(&row[..row_bytes as usize]);
    }
    drop(mapped);
    buffer.unmap();
    gpu.check()?;
    Ok(texels)
}

/// Texels of an `Rgba16Float` texture read back tightly packed, as f32.
pub fn f16_texels(bytes: &[u8]) -> Vec<[f32; 4]> {
    let halves: Vec<[u16; 4]> = bytemuck::pod_collect_to_vec(bytes);
    halves.iter().map(|t| t.map(|bits| half::f16::from_bits(bits).to_f32())).collect()
}
