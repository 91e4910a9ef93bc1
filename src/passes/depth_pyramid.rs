//! How it works: the depth pyramid (Hi-Z) reduces the terrain's reversed-Z depth (1 near, 0 for
//! the sky) into an R32Float mip chain in which each texel holds the *minimum* depth, i.e. the
//! farthest surface, of the pixels it covers. Level 0 is half the target's size; every level
//! halves the one below, rounding down as wgpu's mip sizes do, and the last texel of an odd edge
//! takes three texels below it, so the reduction is conservative at any size. A pixel (x, y)
//! therefore belongs to texel `min(x >> (level + 1), width(level) - 1)` (and likewise in y) at
//! every level: a screen rectangle reads a bounded number of texels and sees every pixel in it.
//!
//! One compute dispatch per level, each reading the level below through a view of that single
//! mip (wgpu tracks usage per mip, so level L can be written while level L − 1 is read).

use crate::gpu::readback::read_texture_mip;
use crate::gpu::{Gpu, GpuError};
use crate::reference::tile_load_map::HizMips;
use crate::shaders;

/// Workgroup edge of the reduction dispatches (handed to WGSL through the prelude).
pub const HIZ_WORKGROUP: u32 = 8;
pub const HIZ_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

pub struct DepthPyramid {
    // Kept to build the bind group over the depth view `encode` is given (a view only lives as
    // long as its caller's frame; the mip-to-mip bind groups are built once, here).
    device: wgpu::Device,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    sizes: Vec<[u32; 2]>,
    from_depth: wgpu::ComputePipeline,
    from_depth_layout: wgpu::BindGroupLayout,
    from_mip: wgpu::ComputePipeline,
    /// Bind group of level `i + 1` (reads level `i`).
    mip_groups: Vec<wgpu::BindGroup>,
    mip_views: Vec<wgpu::TextureView>,
}

/// Sizes of the levels of the pyramid of a `width` × `height` depth target.
pub fn level_sizes(width: u32, height: u32) -> Vec<[u32; 2]> {
    let mut sizes = vec![[(width / 2).max(1), (height / 2).max(1)]];
    while let Some(&[w, h]) = sizes.last().filter(|s| s[0] > 1 || s[1] > 1) {
        sizes.push([(w / 2).max(1), (h / 2).max(1)]);
    }
    sizes
}

impl DepthPyramid {
    /// A pyramid for a `width` × `height` Depth32Float target.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let sizes = level_sizes(width, height);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("depth pyramid"),
            size: wgpu::Extent3d { width: sizes[0][0], height: sizes[0][1], depth_or_array_layers: 1 },
            mip_level_count: sizes.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HIZ_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let mip_views: Vec<wgpu::TextureView> = (0..sizes.len() as u32)
            .map(|level| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    base_mip_level: level,
                    mip_level_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let module = shaders::module(device, "depth_pyramid");
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let destination = entry(
            1,
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: HIZ_FORMAT,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
        );
        let texture_entry = |binding, sample_type| {
            entry(
                binding,
                wgpu::BindingType::Texture {
                    sample_type,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            )
        };
        let from_depth_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth pyramid from depth"),
            entries: &[texture_entry(0, wgpu::TextureSampleType::Depth), destination],
        });
        let from_mip_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth pyramid from mip"),
            entries: &[texture_entry(2, wgpu::TextureSampleType::Float { filterable: false }), destination],
        });
        let pipeline = |layout: &wgpu::BindGroupLayout, entry_point: &str| {
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(entry_point),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let from_depth = pipeline(&from_depth_layout, "reduce_depth");
        let from_mip = pipeline(&from_mip_layout, "reduce_mip");
        let mip_groups = mip_views
            .windows(2)
            .map(|pair| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("depth pyramid level"),
                    layout: &from_mip_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::TextureView(&pair[0]),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&pair[1]),
                        },
                    ],
                })
            })
            .collect();
        Self {
            device: device.clone(),
            texture,
            view,
            sizes,
            from_depth,
            from_depth_layout,
            from_mip,
            mip_groups,
            mip_views,
        }
    }

    /// Records the reduction of `depth` (a view of the Depth32Float target this pyramid was
    /// sized for) into every level.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, depth: &wgpu::TextureView) {
        let first = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth pyramid level 0"),
            layout: &self.from_depth_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(depth) },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&self.mip_views[0]),
                },
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("depth pyramid"),
            timestamp_writes: None,
        });
        let groups = |[w, h]: [u32; 2]| (w.div_ceil(HIZ_WORKGROUP), h.div_ceil(HIZ_WORKGROUP));
        pass.set_pipeline(&self.from_depth);
        pass.set_bind_group(0, &first, &[]);
        let (x, y) = groups(self.sizes[0]);
        pass.dispatch_workgroups(x, y, 1);
        pass.set_pipeline(&self.from_mip);
        for (group, &size) in self.mip_groups.iter().zip(&self.sizes[1..]) {
            pass.set_bind_group(0, group, &[]);
            let (x, y) = groups(size);
            pass.dispatch_workgroups(x, y, 1);
        }
    }

    /// The whole mip chain, for passes that test against it (`textureLoad(t, texel, level)`).
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    pub fn mips(&self) -> u32 {
        self.sizes.len() as u32
    }

    /// Size of each level, texels.
    pub fn sizes(&self) -> &[[u32; 2]] {
        &self.sizes
    }

    /// Reads every level back, waiting for the GPU: for tests and tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu) -> Result<HizMips, GpuError> {
        let levels = (0..self.sizes.len() as u32)
            .map(|mip| {
                let bytes = read_texture_mip(gpu, &self.texture, mip, wgpu::TextureAspect::All, 4)?;
                Ok(bytemuck::pod_collect_to_vec::<u8, f32>(&bytes))
            })
            .collect::<Result<Vec<_>, GpuError>>()?;
        Ok(HizMips { sizes: self.sizes.clone(), levels })
    }
}
