//! What a host program uses of terramp, in one place: `use terramp::host::*` (docs/host.md says
//! how each piece is used).
//!
//! How it works: this module defines nothing; it re-exports, from the modules that define them,
//! the types and functions a program drawing terramp into its own frame or asking it about the
//! ground needs, and the `wgpu` and `glam` it is built on, so that a host names the same versions.
//! The examples import terramp only through it (`tests/examples.rs` checks their `use` lines), so
//! an item a host needs and this module lacks shows up as a failing example, and a change to this
//! list is a change to the host API, seen in review.

pub use bytemuck;
pub use glam;
pub use wgpu;

/// The camera: an f64 position in the dataset's CRS, heading, pitch, roll, field of view and near
/// plane; made from a host's rotation or matrices (`Camera::from_matrices`).
pub use crate::camera::{Camera, CameraError, HostCameraError};
/// The settings (`config/default.toml` and its presets), and the error reading them.
pub use crate::config::{Settings, SettingsError};
/// A built dataset, opened; a camera placed in it from the Earth or from text, and why not.
pub use crate::dataset::Dataset;
pub use crate::dataset::pose::CameraPoseError;
/// A camera given on the Earth (WGS 84 longitude, latitude, height, true heading) and its place in
/// a dataset's CRS (`Dataset::place_on_earth`).
pub use crate::earth::pose::{CrsPose, GeoPose};
/// The renderer, what it draws into, and what it answers about the ground and the plants.
pub use crate::frame::{
    FrameReport, GroundAt, HostTargetError, HostTargets, Plant, Plants, RenderError, Renderer,
};
/// A texture's texels read back (waits for the GPU): for a host saving its frame.
pub use crate::gpu::readback::read_texture;
/// The device: terramp's own (`Gpu::new`) or the host's (`Gpu::from_host`).
pub use crate::gpu::{AdapterChoice, Gpu, GpuError};
/// The limits a host's device must allow for terramp's passes.
pub use crate::passes::limits::needed_limits;
/// The host's depth format, and the format of a linear HDR host colour (sRGB formats take the
/// frame display-ready).
pub use crate::passes::{DEPTH_FORMAT, HOST_HDR_FORMAT};
/// The ground the last frame drew (`Renderer::drawn_ground`): picks and heights on it.
pub use crate::reference::terrain::{DrawnGround, GroundPoint};
/// A synthetic dataset, for a host to try terramp without data of its own.
#[cfg(feature = "synth")]
pub use crate::synth::{SynthError, SynthParams, synthesize};
