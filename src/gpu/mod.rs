//! How it works: everything terramp asks of the GPU outside the passes themselves: the constants
//! and bit layouts shared with WGSL (`layout`, a leaf) and the prelude and sources generated from
//! them (`shaders`), the `#[repr(C)]` structs that cross to WGSL (`gpu_types`, checked through
//! `struct_layout`), binding tables (`bindings`) and the resources passes build (`resources`),
//! picking and opening a headless device (`device`) and its counted queue (`queue`), timing passes
//! (`profiler`), counting what each asked of the GPU (`counts`, recorded through `counter`) and
//! their fragments against the pixels they cover (`fragments`), and reading back:
//! blocking for tools and tests (`readback`), non-blocking for the frame (`readback_ring`).

pub mod bindings;
pub mod counter;
pub mod counts;
pub mod device;
pub mod fragments;
pub mod gpu_types;
pub mod layout;
pub mod profiler;
pub mod queue;
pub mod readback;
pub mod readback_ring;
pub mod resources;
pub mod shaders;
pub mod struct_layout;

pub use device::{ADAPTER_VARIABLE, AdapterChoice, Gpu, GpuError, skip_device_select_layer};
pub use profiler::{PassTiming, Profiler, TimeSource};
pub use queue::Queue;
