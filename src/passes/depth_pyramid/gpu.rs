//! The depth pyramid's GPU half: the two reduction pipelines with their binding tables (the first
//! level reads the depth target, every other the level below), built once, and the recorded
//! reduction.

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension as Dim};

use crate::gpu::bindings::{Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::layout::HIZ_WORKGROUP;
use crate::gpu::readback::read_texture_mip;
use crate::gpu::resources::{compute_pipeline, pipeline_layout};
use crate::gpu::shaders::WgslSource;
use crate::gpu::{Gpu, GpuError};

use super::frame::{HizMips, level_sizes};

/// The pyramid's texel format: one reversed-Z depth per texel, which storage textures can write.
pub const HIZ_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The depth pyramid's shader.
pub const SHADER: WgslSource =
    WgslSource { name: "depth_pyramid", parts: &[include_str!("../../../shaders/depth_pyramid.wgsl")] };

/// `reduce_depth`: the depth target into level 0.
pub const FROM_DEPTH: BindingTable<2> = BindingTable {
    label: "depth pyramid from depth",
    bindings: [
        Binding::texture(0, "source_depth", Stage::COMPUTE, TextureSampleType::Depth, Dim::D2),
        Binding::storage_texture(1, "destination", Stage::COMPUTE, HIZ_FORMAT, Dim::D2),
    ],
};

/// `reduce_mip`: one level into the next.
pub const FROM_MIP: BindingTable<2> = BindingTable {
    label: "depth pyramid from mip",
    bindings: [
        Binding::texture(
            2,
            "source_mip",
            Stage::COMPUTE,
            TextureSampleType::Float { filterable: false },
            Dim::D2,
        ),
        Binding::storage_texture(1, "destination", Stage::COMPUTE, HIZ_FORMAT, Dim::D2),
    ],
};

/// The Hi-Z pyramid on the GPU: its texture, per-mip views, pipelines and mip-to-mip bind groups built
/// once in `new` for one target size; `encode` records the reduction of each frame's depth.
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
        let module = SHADER.module(device);
        let from_depth_layout = FROM_DEPTH.layout(device);
        let from_mip_layout = FROM_MIP.layout(device);
        let pipeline = |layout: &wgpu::BindGroupLayout, entry_point: &str| {
            let pipeline_layout = pipeline_layout(device, entry_point, &[layout]);
            compute_pipeline(device, entry_point, &pipeline_layout, &module, entry_point)
        };
        let from_depth = pipeline(&from_depth_layout, "reduce_depth");
        let from_mip = pipeline(&from_mip_layout, "reduce_mip");
        use wgpu::BindingResource::TextureView as View;
        let mip_groups = mip_views
            .windows(2)
            .map(|pair| FROM_MIP.bind_group(device, &from_mip_layout, [View(&pair[0]), View(&pair[1])]))
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
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::TextureView,
        counting: Counting<'_>,
    ) {
        use wgpu::BindingResource::TextureView as View;
        let first = FROM_DEPTH.bind_group(
            &self.device,
            &self.from_depth_layout,
            [View(depth), View(&self.mip_views[0])],
        );
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("depth pyramid"),
            timestamp_writes: None,
        });
        let groups = |[w, h]: [u32; 2]| (w.div_ceil(HIZ_WORKGROUP), h.div_ceil(HIZ_WORKGROUP));
        counting.begin(&mut pass, Part::Whole);
        pass.set_pipeline(&self.from_depth);
        pass.set_bind_group(0, &first, &[]);
        let (x, y) = groups(self.sizes[0]);
        counting.dispatch(&mut pass, [x, y, 1]);
        pass.set_pipeline(&self.from_mip);
        for (group, &size) in self.mip_groups.iter().zip(&self.sizes[1..]) {
            pass.set_bind_group(0, group, &[]);
            let (x, y) = groups(size);
            counting.dispatch(&mut pass, [x, y, 1]);
        }
        counting.end(&mut pass);
    }

    /// The whole mip chain, for passes that test against it (`textureLoad(t, texel, level)`).
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Levels in the pyramid, down to 1 × 1 texel.
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
