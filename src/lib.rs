//! terramp amplifies real terrain on the GPU.
//!
//! It streams a large DEM with its aerial imagery and populates the ground with seeds chosen from
//! a land-cover map, in the four passes of Amara, Meunier & Marsault (2007). See `DESIGN.md` in
//! the shared folder for the architecture; `frame` reads as the list of passes.

#![warn(missing_docs)]
#[cfg(feature = "bake")]
pub mod bake;
pub mod camera;
pub mod classes;
pub mod config;
pub mod dataset;
pub mod frame;
pub mod gpu;
pub mod impostor;
pub mod passes;
pub mod path;
pub mod profile;
pub mod reference;
pub mod seeds;
pub mod streaming;
#[cfg(feature = "sweep")]
pub mod sweep;
#[cfg(feature = "synth")]
pub mod synth;
