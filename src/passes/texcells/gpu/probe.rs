//! The texcell shader's per-fragment choices run on chosen points, for the test that holds them
//! equal to their twin (`reference::texcells`): `probe_forest_uv` (compute, in
//! `shaders/texcells.wgsl`) maps each point to where it reads the forest sample, through the very
//! `forest_uv` the fragments call, with the pass's own uniforms (group 1, binding 0 alone).

use wgpu::ShaderStages as Stage;

use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::gpu_types::TexcellUniforms;
use crate::gpu::layout::TEXCELL_PROBE_WORKGROUP;
use crate::gpu::readback::read_values;
use crate::gpu::resources::{buffer, buffer_init, compute_pipeline, pipeline_layout};
use crate::gpu::{Gpu, GpuError};

use super::SHADER;

/// The probe's view of group 1: the uniforms only.
pub const PROBE_UNIFORMS: BindingTable<1> = BindingTable {
    label: "texcell probe uniforms",
    bindings: [Binding::uniform::<TexcellUniforms>(0, "tu", Stage::COMPUTE)],
};

/// Group 2: the points in, the sample coordinates out.
pub const PROBE_BINDINGS: BindingTable<2> = BindingTable {
    label: "texcell probe",
    bindings: [
        Binding::storage_array::<[f32; 2]>(0, "probe_points", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<[f32; 2]>(1, "probe_uvs", Stage::COMPUTE, Access::ReadWrite),
    ],
};

/// Where each of `points_m` (grid space, metres) reads the forest sample under `uniforms`, in
/// sample units, as the texcell shader computes it. Blocking: for tests.
pub fn probe_forest_uv(
    gpu: &Gpu,
    uniforms: &TexcellUniforms,
    points_m: &[[f32; 2]],
) -> Result<Vec<[f32; 2]>, GpuError> {
    let device = &gpu.device;
    let module = SHADER.module(device);
    let empty =
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: None, entries: &[] });
    let (own, probe) = (PROBE_UNIFORMS.layout(device), PROBE_BINDINGS.layout(device));
    let layout = pipeline_layout(device, "texcell probe", &[&empty, &own, &probe]);
    let pipeline = compute_pipeline(device, "texcell probe", &layout, &module, "probe_forest_uv");
    use wgpu::BufferUsages as U;
    let u = buffer_init(device, "texcell probe uniforms", bytemuck::bytes_of(uniforms), U::UNIFORM);
    let points = if points_m.is_empty() { &[[0.0; 2]][..] } else { points_m };
    let input = buffer_init(device, "probe points", bytemuck::cast_slice(points), U::STORAGE);
    let bytes = size_of_val(points) as u64;
    let output = buffer(device, "probe uvs", bytes, U::STORAGE | U::COPY_SRC);
    let empty_group =
        device.create_bind_group(&wgpu::BindGroupDescriptor { label: None, layout: &empty, entries: &[] });
    let own_group = PROBE_UNIFORMS.bind_group(device, &own, [u.as_entire_binding()]);
    let probe_group =
        PROBE_BINDINGS.bind_group(device, &probe, [input.as_entire_binding(), output.as_entire_binding()]);
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &empty_group, &[]);
        pass.set_bind_group(1, &own_group, &[]);
        pass.set_bind_group(2, &probe_group, &[]);
        pass.dispatch_workgroups((points.len() as u32).div_ceil(TEXCELL_PROBE_WORKGROUP), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let mut uvs = read_values::<[f32; 2]>(gpu, &output, points.len() as u64)?;
    uvs.truncate(points_m.len());
    Ok(uvs)
}
