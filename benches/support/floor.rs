//! The floor of a compute pass (issue 19): a trivial kernel that reads as many bytes as the pass
//! reads and writes as many as it writes, on the same adapter, timed the same way. A pass is
//! reported as a multiple of its floor: what its work costs beyond moving its bytes once.
//!
//! The kernel reads `in_words` words and writes `out_words`, each exactly once, in a grid-stride
//! loop of 256-wide workgroups; a word past the output is folded into a condition that is always
//! false at run time (the uniform's pad is 0), so no read is optimised away.

#![allow(dead_code, reason = "each bench uses a part of it")]

use std::time::Instant;

use terramp::gpu::Gpu;
use wgpu::util::DeviceExt;

const SHADER: &str = "
struct Sizes { in_words: u32, out_words: u32, threads: u32, pad: u32 }
@group(0) @binding(0) var<storage, read> src: array<u32>;
@group(0) @binding(1) var<storage, read_write> dst: array<u32>;
@group(0) @binding(2) var<uniform> sizes: Sizes;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let words = max(sizes.in_words, sizes.out_words);
    for (var i = id.x; i < words; i += sizes.threads) {
        var v = 0u;
        if i < sizes.in_words { v = src[i]; }
        if i < sizes.out_words { dst[i] = v ^ i; } else if v == 0xdeadbeefu && sizes.pad == 1u { dst[0] = v; }
    }
}";

/// Most workgroups one dispatch launches (the grid-stride loop covers the rest).
const MAX_GROUPS: u32 = 65_535;

/// The floor kernel for one pass's byte counts.
pub struct Floor {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    groups: u32,
}

impl Floor {
    /// A kernel reading `in_bytes` and writing `out_bytes` (each rounded up to whole words).
    pub fn new(gpu: &Gpu, in_bytes: u64, out_bytes: u64) -> Self {
        let device = &gpu.device;
        let words = |bytes: u64| bytes.div_ceil(4).max(1) as u32;
        let (in_words, out_words) = (words(in_bytes), words(out_bytes));
        let groups = in_words.max(out_words).div_ceil(256).min(MAX_GROUPS);
        let buffer = |label, words: u32, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: u64::from(words) * 4,
                usage,
                mapped_at_creation: false,
            })
        };
        let src = buffer("floor in", in_words, wgpu::BufferUsages::STORAGE);
        let dst = buffer("floor out", out_words, wgpu::BufferUsages::STORAGE);
        let sizes = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("floor sizes"),
            contents: bytemuck::cast_slice(&[in_words, out_words, groups * 256, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("floor"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("floor"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("floor"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: src.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: dst.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: sizes.as_entire_binding() },
            ],
        });
        Self { pipeline, bind_group, groups }
    }

    /// Records one run.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.groups, 1, 1);
    }
}

/// Median wall time of `runs` submissions of what `record` records (each submitted alone, waited
/// for), ms, after a warm-up run.
pub fn median_ms(gpu: &Gpu, runs: usize, record: impl Fn(&mut wgpu::CommandEncoder)) -> f64 {
    let run = || {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        record(&mut encoder);
        let start = Instant::now();
        gpu.queue.submit([encoder.finish()]);
        gpu.wait().expect("wait");
        start.elapsed().as_secs_f64() * 1e3
    };
    run();
    let mut ms: Vec<f64> = (0..runs.max(1)).map(|_| run()).collect();
    ms.sort_by(f64::total_cmp);
    ms[ms.len() / 2]
}
