//! How it works: a CPU twin of every GPU pass whose output the CPU or the tests rely on, written
//! shader-shaped (same structure, same f32 arithmetic in the same order), so tests can demand
//! GPU == CPU exactly for integer outputs. The exact oracle used to measure accuracy (f64, full
//! resolution) is separate from these twins: a twin reproduces the GPU, the oracle judges it.
//! `accuracy` (seeds against the oracle), `image_metrics` (PSNR, SSIM of frames against the
//! ground truth) and `frame_change` (popping: 4 × 4 block changes between consecutive frames,
//! against the truth's along the same flight) are what the speed trade (`sweep`) reports; `worst`
//! takes error maxima that never drop a NaN; `slicing` measures the slicings' stochastic blend
//! against the paper's sorted one; `terrain` rebuilds the ground a frame drew, for the host's
//! picks and heights.

pub mod accuracy;
pub mod atmosphere;
pub mod compact;
pub mod depth_pyramid;
pub mod display;
pub mod frame_change;
pub mod image_metrics;
pub mod oracle;
pub mod seed_select;
pub mod slicing;
pub mod terrain;
pub mod texcells;
pub mod tile_load_map;
pub mod worst;
