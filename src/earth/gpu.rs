//! How it works: the mapping's shader side. `shaders/shared/earth.wgsl` holds `EarthNode` (a
//! node's `NodeMapping`, as the GPU reads it) and `earth_position_m`, the polynomial every pass
//! that places a point on the Earth is to call; `probe_positions` runs it on chosen points (the
//! compute entry of `shaders/earth.wgsl`) for the test that holds it to its Rust twin, and
//! `probe_stand` runs `earth_stand` (what stands a seed's model on its place).

use wgpu::ShaderStages as Stage;

use super::local::NodeMapping;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::gpu_types::{EarthNode, EarthProbePoint};
use crate::gpu::layout::EARTH_PROBE_WORKGROUP;
use crate::gpu::readback::read_values;
use crate::gpu::resources::{buffer, buffer_init, compute_pipeline, pipeline_layout};
use crate::gpu::shaders::WgslSource;
use crate::gpu::{Gpu, GpuError};

/// The mapping's shared WGSL: `EarthNode` and `earth_position_m`.
pub const EARTH: &str = include_str!("../../shaders/shared/earth.wgsl");

/// The probe's shader.
pub const SHADER: WgslSource =
    WgslSource { name: "earth", parts: &[EARTH, include_str!("../../shaders/earth.wgsl")] };

/// The probe's bindings: the nodes and points in, the positions out.
pub const PROBE_BINDINGS: BindingTable<3> = BindingTable {
    label: "earth probe",
    bindings: [
        Binding::storage_array::<EarthNode>(0, "probe_nodes", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<EarthProbePoint>(1, "probe_points", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<[f32; 4]>(2, "probe_positions", Stage::COMPUTE, Access::ReadWrite),
    ],
};

impl From<&NodeMapping> for EarthNode {
    fn from(m: &NodeMapping) -> Self {
        let v = |v: glam::Vec3| v.extend(0.0).to_array();
        Self {
            origin_m: v(m.origin_m),
            d_x: v(m.d_x),
            d_y: v(m.d_y),
            d_h: v(m.d_h),
            d_xx: v(m.d_xx),
            d_xy: v(m.d_xy),
            d_yy: v(m.d_yy),
            d_xh: v(m.d_xh),
            d_yh: v(m.d_yh),
        }
    }
}

impl From<&EarthNode> for NodeMapping {
    fn from(n: &EarthNode) -> Self {
        let v = |v: [f32; 4]| glam::Vec3::new(v[0], v[1], v[2]);
        Self {
            origin_m: v(n.origin_m),
            d_x: v(n.d_x),
            d_y: v(n.d_y),
            d_h: v(n.d_h),
            d_xx: v(n.d_xx),
            d_xy: v(n.d_xy),
            d_yy: v(n.d_yy),
            d_xh: v(n.d_xh),
            d_yh: v(n.d_yh),
        }
    }
}

/// Where the shader places each of `points` on its node of `nodes` (camera-relative metres).
/// Blocking: for tests.
pub fn probe_positions(
    gpu: &Gpu,
    nodes: &[EarthNode],
    points: &[EarthProbePoint],
) -> Result<Vec<[f32; 3]>, GpuError> {
    probe(gpu, nodes, points, "probe_earth_positions")
}

/// Each of `points`' offset, as a vector, stood by the shader's `earth_stand` on its node's
/// vertical (`d_h`). Blocking: for tests.
pub fn probe_stand(
    gpu: &Gpu,
    nodes: &[EarthNode],
    points: &[EarthProbePoint],
) -> Result<Vec<[f32; 3]>, GpuError> {
    probe(gpu, nodes, points, "probe_earth_stand")
}

fn probe(
    gpu: &Gpu,
    nodes: &[EarthNode],
    points: &[EarthProbePoint],
    entry: &str,
) -> Result<Vec<[f32; 3]>, GpuError> {
    if points.is_empty() || nodes.is_empty() {
        return Ok(Vec::new());
    }
    let device = &gpu.device;
    let module = SHADER.module(device);
    let group = PROBE_BINDINGS.layout(device);
    let layout = pipeline_layout(device, "earth probe", &[&group]);
    let pipeline = compute_pipeline(device, "earth probe", &layout, &module, entry);
    use wgpu::BufferUsages as U;
    let nodes = buffer_init(device, "earth probe nodes", bytemuck::cast_slice(nodes), U::STORAGE);
    let input = buffer_init(device, "earth probe points", bytemuck::cast_slice(points), U::STORAGE);
    let bytes = (size_of::<[f32; 4]>() * points.len()) as u64;
    let output = buffer(device, "earth probe positions", bytes, U::STORAGE | U::COPY_SRC);
    let bind_group = PROBE_BINDINGS.bind_group(
        device,
        &group,
        [nodes.as_entire_binding(), input.as_entire_binding(), output.as_entire_binding()],
    );
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((points.len() as u32).div_ceil(EARTH_PROBE_WORKGROUP), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    let positions = read_values::<[f32; 4]>(gpu, &output, points.len() as u64)?;
    Ok(positions.into_iter().map(|p| [p[0], p[1], p[2]]).collect())
}
