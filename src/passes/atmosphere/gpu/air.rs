//! The air as the lit passes bind it (`shaders/shared/air.wgsl`): the atmosphere's uniforms, the
//! daylight balance, the transmittance and sky-irradiance tables (the light that reaches a
//! point), the aerial-perspective volume with its sampler and the multiple-scattering table (the
//! air between it and the camera, from the volume or marched from high up), one bind group at
//! `AIR_GROUP` that the ground, the seeds and the texcells set. Each of them holds its pipelines
//! in the air's two variants (`AirVariants`: the shader's `AIR_MARCHED` constant), the marched one
//! made the first time a view above `SKY_MARCHED_ABOVE_KM` needs it.

use std::cell::Cell;
use std::sync::OnceLock;

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension as Dim};

use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::gpu_types::AtmosphereUniforms;

/// The bind group index of the air in every lit pass's pipeline (`@group(2)` in
/// `shared/air.wgsl`; `tests/shaders.rs` holds the two equal).
pub const AIR_GROUP: u32 = 2;

const STAGES: Stage = Stage::VERTEX_FRAGMENT;
const LUT: TextureSampleType = TextureSampleType::Float { filterable: false };
const VOLUME: TextureSampleType = TextureSampleType::Float { filterable: true };

/// `shared/air.wgsl`'s bindings: the seeds' vertex stage reads the light too (their colour
/// follow-up's yardstick).
pub const AIR_BINDINGS: BindingTable<8> = BindingTable {
    label: "air",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(10, "atmosphere", STAGES, Access::Read),
        Binding::uniform::<[f32; 4]>(11, "daylight", STAGES),
        Binding::texture(12, "transmittance", STAGES, LUT, Dim::D2),
        Binding::texture(13, "irradiance", STAGES, LUT, Dim::D2),
        Binding::texture(14, "aerial_inscatter", STAGES, VOLUME, Dim::D3),
        Binding::texture(15, "aerial_transmittance", STAGES, VOLUME, Dim::D3),
        Binding::sampler(16, "aerial_sampler", STAGES, wgpu::SamplerBindingType::Filtering),
        Binding::texture(17, "multiple", STAGES, LUT, Dim::D2),
    ],
};

/// The air's bind group layout and its one bind group (every resource in it lives as long as the
/// atmosphere pass and keeps its size), and whether this frame's view marches its air.
pub struct Air {
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    /// Set by the atmosphere pass's `prepare`: the view is above `SKY_MARCHED_ABOVE_KM`.
    pub(super) marched: Cell<bool>,
}

impl Air {
    /// Over the atmosphere pass's `uniforms`, `daylight` balance, (transmittance, irradiance,
    /// multiple-scattering) tables, aerial-perspective `volume` (in-scattering, transmittance)
    /// and its `sampler`.
    pub fn new(
        device: &wgpu::Device,
        uniforms: &wgpu::Buffer,
        daylight: &wgpu::Buffer,
        [transmittance, irradiance, multiple]: [&wgpu::TextureView; 3],
        volume: &[wgpu::TextureView; 2],
        sampler: &wgpu::Sampler,
    ) -> Self {
        use wgpu::BindingResource::TextureView as View;
        let layout = AIR_BINDINGS.layout(device);
        let group = AIR_BINDINGS.bind_group(
            device,
            &layout,
            [
                uniforms.as_entire_binding(),
                daylight.as_entire_binding(),
                View(transmittance),
                View(irradiance),
                View(&volume[0]),
                View(&volume[1]),
                wgpu::BindingResource::Sampler(sampler),
                View(multiple),
            ],
        );
        Self { layout, group, marched: Cell::new(false) }
    }

    /// The layout a lit pass's pipeline holds at `AIR_GROUP`.
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The group a lit pass sets at `AIR_GROUP`.
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }

    /// Whether this frame's view marches its air per pixel (and its sky): which of a lit pass's
    /// `AirVariants` it draws with.
    pub fn marched(&self) -> bool {
        self.marched.get()
    }
}

/// The shader constant that picks a lit pipeline's air (`override AIR_MARCHED` in
/// `shared/air.wgsl`), for `PipelineCompilationOptions::constants`.
pub fn air_constants(marched: bool) -> [(&'static str, f64); 1] {
    [("AIR_MARCHED", f64::from(u8::from(marched)))]
}

/// A lit pass's pipeline (or set of pipelines) in the air's two variants: read from the volume,
/// made at once, and marched per pixel, made by the same `make` the first time a view needs it
/// (most renderers never fly above 30 km, and each pipeline costs time to build).
pub struct AirVariants<T> {
    volume: T,
    marched: OnceLock<T>,
    make: Box<dyn Fn(bool) -> T + Send + Sync>,
}

impl<T> AirVariants<T> {
    /// The volume's variant made now by `make(false)`; `make(true)` later, when asked for.
    pub fn new(make: impl Fn(bool) -> T + Send + Sync + 'static) -> Self {
        Self { volume: make(false), marched: OnceLock::new(), make: Box::new(make) }
    }

    /// The variant for `air`'s view.
    pub fn get(&self, air: &Air) -> &T {
        self.of(air.marched())
    }

    /// The variant that marches (`marched`) or reads the volume.
    pub fn of(&self, marched: bool) -> &T {
        if marched { self.marched.get_or_init(|| (self.make)(true)) } else { &self.volume }
    }
}

/// The layout of a pipeline that lights what it draws: its own `groups` from 0, then the air's
/// `air` at `AIR_GROUP` (the indices between left empty).
pub fn pipeline_layout_with_air(
    device: &wgpu::Device,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
    air: &wgpu::BindGroupLayout,
) -> wgpu::PipelineLayout {
    let air_group = AIR_GROUP as usize;
    let mut layouts: Vec<Option<&wgpu::BindGroupLayout>> = vec![None; air_group + 1];
    for (slot, group) in layouts.iter_mut().zip(groups) {
        *slot = Some(*group);
    }
    layouts[air_group] = Some(air);
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    })
}
