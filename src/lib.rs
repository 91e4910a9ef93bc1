//! terramp amplifies real terrain on the GPU.
//!
//! It streams a large DEM with its aerial imagery and populates the ground with seeds chosen from
//! a land-cover map, in the four passes of Amara, Meunier & Marsault (2007). `ARCHITECTURE.md` at
//! the repository's root is the map of the code: the passes and their folders (`passes`, with
//! their twins in `reference`), one frame's data flow (`frame`), the layers modules may import
//! from, and where constants (`gpu::layout`) and GPU types (`gpu::gpu_types`) live. The design
//! behind it is `DESIGN.md` in the shared folder.
//!
//! # In your program
//!
//! [`host`] gathers what a host program uses: a [`frame::Renderer`] made on terramp's own device
//! or the host's ([`gpu::Gpu::from_host`], with [`passes::limits::needed_limits`]), drawing over
//! the host's colour and depth ([`frame::Renderer::render_into`]) or recording into its command
//! encoder ([`frame::Renderer::encode_frame`]), from a [`camera::Camera`] in f64 or the host's own
//! matrices ([`camera::Camera::from_matrices`]); and the questions a simulation asks, answered on
//! the CPU: the ground's height and normal ([`frame::Renderer::ground_at`]), a pick through a pixel
//! ([`frame::Renderer::drawn_ground`]), the land cover ([`frame::Renderer::land_cover_at`]) and the
//! plants near a point ([`frame::Renderer::plants_near`]). `docs/host.md` in the repository says
//! what a host must match; `examples/queries_along_path.rs` is a headless host:
//!
//! ```text
//! cargo run --example queries_along_path -- [DATASET] [--points N] [--radius M]
//! ```
//!
//! # The data it needs
//!
//! A dataset folder: a DEM, its imagery and, for the seeds, a land-cover map, as tiled packs and a
//! manifest ([`dataset::Dataset::open`]). `terramp-data build` (the workspace's `data-tools`) makes
//! one from GeoTIFFs with GDAL; `synth::synthesize` (feature `synth`) makes a synthetic one with
//! no input at all. The trees are drawn from impostors baked from glTF models (`terramp-data
//! bake`, or `bake`, feature `bake`) or grown by the tree generator (`tree`, feature `synth`).
//!
//! # Features
//!
//! The renderer (frame, passes, streaming, profiler, twins, oracle, queries) needs none of them:
//! `default-features = false` builds it without winit, egui, clap or any offline tool.
//! - `cli` (default): the `terramp` command line; `viewer` (default): `terramp view`, a window
//!   (winit) with an overlay (egui); `tools` (default): every offline tool below.
//! - `bake`: the impostor baker (glTF); `synth`: the synthetic dataset and the tree generator;
//!   `bc-encode`: imagery packs of BC1/BC7 blocks; `sweep`: the speed trade and its plot;
//!   `flip`: frame error against the ground truth with NVIDIA's FLIP.
//!
//! The minimum Rust is the workspace's `rust-version` (egui's, for the viewer), which clippy's
//! `incompatible_msrv` lint holds the code to.
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
