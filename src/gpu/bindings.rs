//! How it works: a pass declares each of its bind groups once, as a `BindingTable`: per binding
//! its number, the WGSL global it binds, the stages that see it and what it is (a uniform or
//! storage buffer of a Rust type, a texture, a storage texture, a sampler). The same table builds
//! the bind group layout (`layout`) and, from resources given in table order, the bind group
//! (`bind_group`), so the numbers are written once on the Rust side. `tests/shaders.rs` checks
//! every table against the `@group(g) @binding(n)` globals of its shader with naga: name, kind,
//! texture type, buffer size (or element stride), access and the stages that read it.

use wgpu::{ShaderStages, TextureSampleType, TextureViewDimension};

/// What one binding is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BindingKind {
    /// A uniform buffer holding one value of `bytes`.
    Uniform {
        /// Size of the value, bytes (`size_of` of the Rust twin of its WGSL type).
        bytes: u64,
    },
    /// A storage buffer holding one value of `bytes` (a struct, or a fixed-size array), or with
    /// `runtime_array` a runtime-sized array of elements of `bytes`.
    Storage {
        /// Declared `var<storage, read>`; else `read_write`.
        read_only: bool,
        /// Size of the value, or with `runtime_array` of one element, bytes.
        bytes: u64,
        /// The WGSL global is a runtime-sized `array<T>`, whose length the bound buffer decides.
        runtime_array: bool,
    },
    /// A sampled (or loaded) texture, never multisampled.
    Texture {
        /// What reading it returns: float (filterable or not), unsigned integer or depth.
        sample_type: TextureSampleType,
        /// The view dimension the shader declares (2D, or a 2D array for the tile caches).
        dimension: TextureViewDimension,
    },
    /// A storage texture the shader only writes (`texture_storage_2d<format, write>`).
    StorageTexture {
        /// The texel format the shader declares and the bound view must have.
        format: wgpu::TextureFormat,
        /// The view dimension the shader declares.
        dimension: TextureViewDimension,
    },
    /// A sampler of this binding type (filtering, non-filtering or comparison).
    Sampler(wgpu::SamplerBindingType),
}

/// One binding of a bind group: its number, the WGSL global it binds, who sees it, what it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Binding {
    /// Its number, the `n` of `@group(0) @binding(n)`.
    pub binding: u32,
    /// The name of the WGSL global (`var<...> name: ...`).
    pub name: &'static str,
    /// The shader stages that see it: must include the stage of every entry point that uses it.
    pub visibility: ShaderStages,
    /// What it binds, with the size, type or format the WGSL declaration must match.
    pub kind: BindingKind,
}

/// Storage access of a buffer binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// `var<storage, read>`: the shader only reads the buffer.
    Read,
    /// `var<storage, read_write>`: the shader writes the buffer (and may read it).
    ReadWrite,
}

impl Binding {
    /// A uniform buffer holding one `T`.
    pub const fn uniform<T>(binding: u32, name: &'static str, visibility: ShaderStages) -> Self {
        Self { binding, name, visibility, kind: BindingKind::Uniform { bytes: size_of::<T>() as u64 } }
    }

    /// A storage buffer holding one `T` (a struct or a fixed-size array).
    pub const fn storage<T>(
        binding: u32,
        name: &'static str,
        visibility: ShaderStages,
        access: Access,
    ) -> Self {
        let read_only = matches!(access, Access::Read);
        let kind = BindingKind::Storage { read_only, bytes: size_of::<T>() as u64, runtime_array: false };
        Self { binding, name, visibility, kind }
    }

    /// A storage buffer holding a runtime-sized array of `T`.
    pub const fn storage_array<T>(
        binding: u32,
        name: &'static str,
        visibility: ShaderStages,
        access: Access,
    ) -> Self {
        let read_only = matches!(access, Access::Read);
        let kind = BindingKind::Storage { read_only, bytes: size_of::<T>() as u64, runtime_array: true };
        Self { binding, name, visibility, kind }
    }

    /// A sampled texture.
    pub const fn texture(
        binding: u32,
        name: &'static str,
        visibility: ShaderStages,
        sample_type: TextureSampleType,
        dimension: TextureViewDimension,
    ) -> Self {
        Self { binding, name, visibility, kind: BindingKind::Texture { sample_type, dimension } }
    }

    /// A write-only storage texture.
    pub const fn storage_texture(
        binding: u32,
        name: &'static str,
        visibility: ShaderStages,
        format: wgpu::TextureFormat,
        dimension: TextureViewDimension,
    ) -> Self {
        Self { binding, name, visibility, kind: BindingKind::StorageTexture { format, dimension } }
    }

    /// A sampler.
    pub const fn sampler(
        binding: u32,
        name: &'static str,
        visibility: ShaderStages,
        ty: wgpu::SamplerBindingType,
    ) -> Self {
        Self { binding, name, visibility, kind: BindingKind::Sampler(ty) }
    }

    fn layout_entry(&self) -> wgpu::BindGroupLayoutEntry {
        let buffer = |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
        let ty = match self.kind {
            BindingKind::Uniform { .. } => buffer(wgpu::BufferBindingType::Uniform),
            BindingKind::Storage { read_only, .. } => buffer(wgpu::BufferBindingType::Storage { read_only }),
            BindingKind::Texture { sample_type, dimension } => {
                wgpu::BindingType::Texture { sample_type, view_dimension: dimension, multisampled: false }
            }
            BindingKind::StorageTexture { format, dimension } => wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format,
                view_dimension: dimension,
            },
            BindingKind::Sampler(ty) => wgpu::BindingType::Sampler(ty),
        };
        wgpu::BindGroupLayoutEntry { binding: self.binding, visibility: self.visibility, ty, count: None }
    }
}

/// A bind group's bindings, in the order its resources are given.
#[derive(Debug, Clone, Copy)]
pub struct BindingTable<const N: usize> {
    /// Debug label of the bind group layout and of every bind group built from the table.
    pub label: &'static str,
    /// The bindings, in the order `bind_group` takes their resources.
    pub bindings: [Binding; N],
}

impl<const N: usize> BindingTable<N> {
    /// The bind group layout of the table.
    pub fn layout(&self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        let entries = self.bindings.map(|b| b.layout_entry());
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.label),
            entries: &entries,
        })
    }

    /// A bind group of `layout` (this table's) over `resources`, one per binding in table order.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        resources: [wgpu::BindingResource<'_>; N],
    ) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry<'_>> = self
            .bindings
            .iter()
            .zip(resources)
            .map(|(b, resource)| wgpu::BindGroupEntry { binding: b.binding, resource })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.label),
            layout,
            entries: &entries,
        })
    }

    /// The bindings, for tests that check them against the WGSL.
    pub fn entries(&self) -> &[Binding] {
        &self.bindings
    }
}

/// A shader's bind group as one pipeline uses it: the table and the entry points it serves. What
/// `tests/shaders.rs` checks against the WGSL.
#[derive(Debug, Clone, Copy)]
pub struct PipelineBindings {
    /// The shader whose `@group(group)` globals the table binds.
    pub shader: &'static super::shaders::WgslSource,
    /// The entry points of `shader` the pipeline runs: every global they use must be in the table.
    pub entry_points: &'static [&'static str],
    /// The bind group the table is (`@group(n)`).
    pub group: u32,
    /// The table's bindings (`BindingTable::bindings`).
    pub bindings: &'static [Binding],
}
