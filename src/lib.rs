//! terramp amplifies real terrain on the GPU.
//!
//! It streams a large DEM with its aerial imagery and populates the ground with seeds chosen from
//! a land-cover map, in the four passes of Amara, Meunier & Marsault (2007). `ARCHITECTURE.md` at
//! the repository's root is the map of the code: the passes and their folders (`passes`, with
//! their twins in `reference`), one frame's data flow (`frame`), the layers modules may import
//! from, and where constants (`gpu::layout`) and GPU types (`gpu::gpu_types`) live. The design
//! behind it is `DESIGN.md` in the shared folder.
#![warn(missing_docs)]

pub mod atmosphere;
#[cfg(feature = "bake")]
pub mod bake;
pub mod camera;
pub mod classes;
pub mod config;
pub mod dataset;
pub mod earth;
pub mod frame;
pub mod gpu;
pub mod host;
pub mod impostor;
pub mod light;
pub mod passes;
pub mod path;
pub mod photo;
pub mod profile;
pub mod publish;
pub mod reference;
pub mod seeds;
pub mod streaming;
pub mod sun;
#[cfg(feature = "sweep")]
pub mod sweep;
#[cfg(feature = "synth")]
pub mod synth;
pub mod texcell;
#[cfg(feature = "synth")]
pub mod tree;
pub mod truth;
