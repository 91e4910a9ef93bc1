//! How it works: every struct that crosses to WGSL is defined through `gpu_struct!`, which adds
//! `#[repr(C)]` and describes the struct's memory as `GpuLayout`: each field's name and byte
//! offset, and the struct flattened into scalar leaves (offset, kind), arrays and nested structs
//! included. `tests/shaders.rs` flattens the WGSL struct of the same name the same way with naga
//! and demands equal leaves and equal offsets for every field both sides name, so a field added,
//! dropped, retyped or moved on one side only fails the test, and so does padding WGSL would add
//! where Rust has none.

/// A scalar as both sides store it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarKind {
    /// A 32-bit float: `f32`, or a component of a WGSL float vector or matrix.
    F32,
    /// A 32-bit unsigned integer: `u32` (in WGSL also `atomic<u32>`).
    U32,
    /// A 32-bit signed integer: `i32`.
    I32,
}

/// One field of a GPU struct as Rust lays it out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldLayout {
    /// The field's name, which the WGSL field shares.
    pub name: &'static str,
    /// Byte offset of the field from the start of the struct (`offset_of!`).
    pub offset: usize,
}

/// The memory of a GPU struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StructLayout {
    /// The struct's name, which its WGSL twin shares.
    pub name: &'static str,
    /// Size of the struct, bytes (`size_of`, trailing padding included).
    pub size: usize,
    /// Its fields in declaration order, each with its byte offset.
    pub fields: Vec<FieldLayout>,
    /// Every scalar, by offset.
    pub leaves: Vec<(usize, ScalarKind)>,
}

/// Types whose memory is a sequence of 4-byte scalars.
pub trait GpuLeaves {
    /// Appends this type's scalars, placed at `base`.
    fn leaves(base: usize, out: &mut Vec<(usize, ScalarKind)>);
}

macro_rules! scalar_leaf {
    ($($ty:ty => $kind:ident),*) => {$(
        impl GpuLeaves for $ty {
            fn leaves(base: usize, out: &mut Vec<(usize, ScalarKind)>) {
                out.push((base, ScalarKind::$kind));
            }
        }
    )*};
}

scalar_leaf!(f32 => F32, u32 => U32, i32 => I32);

impl<T: GpuLeaves, const N: usize> GpuLeaves for [T; N] {
    fn leaves(base: usize, out: &mut Vec<(usize, ScalarKind)>) {
        for i in 0..N {
            T::leaves(base + i * size_of::<T>(), out);
        }
    }
}

impl StructLayout {
    /// The vertex attributes of a vertex struct: field `i` at location `i`, its format from its
    /// scalars (what `wgpu::vertex_attr_array!` would say, derived instead of written again).
    pub fn vertex_attributes(&self) -> Vec<wgpu::VertexAttribute> {
        use wgpu::VertexFormat as F;
        self.fields
            .iter()
            .enumerate()
            .map(|(location, field)| {
                let end = self.fields.get(location + 1).map_or(self.size, |next| next.offset);
                let scalars: Vec<ScalarKind> = self
                    .leaves
                    .iter()
                    .filter(|(o, _)| (field.offset..end).contains(o))
                    .map(|(_, k)| *k)
                    .collect();
                let format = match (scalars.first(), scalars.len()) {
                    (Some(ScalarKind::F32), 1) => F::Float32,
                    (Some(ScalarKind::F32), 2) => F::Float32x2,
                    (Some(ScalarKind::F32), 3) => F::Float32x3,
                    (Some(ScalarKind::F32), 4) => F::Float32x4,
                    (Some(ScalarKind::U32), 1) => F::Uint32,
                    (Some(ScalarKind::U32), 2) => F::Uint32x2,
                    (Some(ScalarKind::I32), 1) => F::Sint32,
                    // `gpu_struct!` vertex structs hold only the formats above: a new one is a
                    // change to this table, which the vertex-layout test would show.
                    _ => F::Uint32,
                };
                wgpu::VertexAttribute {
                    format,
                    offset: field.offset as u64,
                    shader_location: location as u32,
                }
            })
            .collect()
    }
}

/// A struct defined with `gpu_struct!`.
pub trait GpuLayout {
    /// Its layout (name, size, fields, leaves).
    fn layout() -> StructLayout;
}

/// Defines a `#[repr(C)]` struct that crosses to WGSL, with its `GpuLayout` and `GpuLeaves`.
macro_rules! gpu_struct {
    ($(#[$meta:meta])* pub struct $name:ident { $($(#[$fmeta:meta])* pub $field:ident: $ty:ty,)* }) => {
        $(#[$meta])*
        #[repr(C)]
        pub struct $name {
            $($(#[$fmeta])* pub $field: $ty,)*
        }

        impl $crate::gpu::struct_layout::GpuLeaves for $name {
            fn leaves(base: usize, out: &mut Vec<(usize, $crate::gpu::struct_layout::ScalarKind)>) {
                $(<$ty as $crate::gpu::struct_layout::GpuLeaves>::leaves(
                    base + std::mem::offset_of!($name, $field),
                    out,
                );)*
            }
        }

        impl $crate::gpu::struct_layout::GpuLayout for $name {
            fn layout() -> $crate::gpu::struct_layout::StructLayout {
                use $crate::gpu::struct_layout::{FieldLayout, GpuLeaves};
                let mut leaves = Vec::new();
                <$name as GpuLeaves>::leaves(0, &mut leaves);
                $crate::gpu::struct_layout::StructLayout {
                    name: stringify!($name),
                    size: size_of::<$name>(),
                    fields: vec![$(FieldLayout {
                        name: stringify!($field),
                        offset: std::mem::offset_of!($name, $field),
                    }),*],
                    leaves,
                }
            }
        }
    };
}

pub(crate) use gpu_struct;
