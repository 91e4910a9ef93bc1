//! Shared test support of the terramp workspace (a dev-dependency of `terramp` and
//! `terramp-data-tools`): where the shared real data lives (`data`), synthetic datasets built
//! once per test process (`datasets`), a GPU and renderers (`setup`), cameras (`camera`), the
//! frame audit against rays through the f64 DEM (`audit`), the Tile Load Map's GPU-vs-twin
//! harness (`tlm`), golden-image comparison (`images`, over the library's metrics) and the
//! shared models baked into impostors (`impostors`).
//!
//! Tests fail by panicking, so this crate unwraps freely.
#![allow(clippy::unwrap_used, reason = "test support: a failure is a panic that names it")]

pub mod audit;
pub mod camera;
pub mod data;
pub mod datasets;
pub mod earth;
pub mod images;
pub mod impostors;
pub mod memory;
pub mod query;
pub mod setup;
pub mod tlm;
pub mod xvfb;

pub use data::{TempDir, shared_data};
pub use datasets::{synth_dataset, synth_dataset_with};
pub use images::{Golden, differing_pixels, psnr};
pub use impostors::{nc_impostors, nc_sliced_impostors, nc_table_with};
pub use setup::{
    command, gpu, ground_settings, lavapipe_only, renderer, settled_colour, small_settings, texture_2d,
};
