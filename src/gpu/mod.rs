//! How it works: everything terramp asks of the GPU outside the passes themselves: picking and
//! opening a headless device (`device`), timing passes (`profiler`), the `#[repr(C)]` structs that
//! cross to WGSL (`gpu_types`), and reading textures back (`readback`).

pub mod device;
pub mod gpu_types;
pub mod profiler;
pub mod readback;
pub mod readback_ring;

pub use device::{AdapterChoice, Gpu, GpuError};
pub use profiler::{PassTiming, Profiler, TimeSource};
