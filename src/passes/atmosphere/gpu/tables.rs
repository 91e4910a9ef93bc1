//! The atmosphere's tables on the GPU: 2D look-up tables that compute writes and shaders read
//! by hand, and the aerial-perspective volume.

use crate::gpu::counter::Counting;
use crate::gpu::layout::ATMOSPHERE_WORKGROUP;
use crate::gpu::readback::read_texture_mip;
use crate::gpu::{Gpu, GpuError};

use super::SKY_VIEW_FORMAT;

/// One table on the GPU: `blocks` of `size` texels side by side (the multiple-scattering
/// table's terms), made by one thread per texel of a block.
pub(super) struct Table {
    texture: wgpu::Texture,
    pub(super) view: wgpu::TextureView,
    pub(super) size: [u32; 2],
    format: wgpu::TextureFormat,
}

impl Table {
    pub(super) fn new(
        device: &wgpu::Device,
        label: &str,
        size: [u32; 2],
        blocks: u32,
        format: wgpu::TextureFormat,
    ) -> Self {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size[0] * blocks, height: size[1], depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        Self { texture, view, size, format }
    }

    /// The workgroups that cover a block, one thread a texel.
    pub(super) fn workgroups(&self) -> [u32; 3] {
        let [w, h] = self.size.map(|side| side.div_ceil(ATMOSPHERE_WORKGROUP));
        [w, h, 1]
    }

    pub(super) fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, counting: Counting<'_>) {
        counting.dispatch(pass, self.workgroups());
    }

    pub(super) fn read_back(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, GpuError> {
        if self.format == SKY_VIEW_FORMAT {
            let bytes = read_texture_mip(gpu, &self.texture, 0, wgpu::TextureAspect::All, 8)?;
            let halves: Vec<[u16; 4]> = bytemuck::pod_collect_to_vec(&bytes);
            return Ok(halves.iter().map(|t| t.map(|bits| half::f16::from_bits(bits).to_f32())).collect());
        }
        let bytes = read_texture_mip(gpu, &self.texture, 0, wgpu::TextureAspect::All, 16)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

/// One of the aerial-perspective volume's two textures (f16, 3D: tiles across, down, slices).
pub(super) fn aerial_volume(device: &wgpu::Device, label: &str, [w, h, d]: [u32; 3]) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: d },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: SKY_VIEW_FORMAT,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}
