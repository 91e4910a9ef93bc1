//! The atmosphere pass (Hillaire 2020; the model is `atmosphere`): the air's look-up tables made
//! by compute, and the sky drawn from them behind everything the frame holds.
//!
//! How it works: `frame` turns the `[atmosphere]` settings and the view (its camera-relative
//! rays and matrix, its zenith, its altitude, the sun) into `AtmosphereUniforms`. `gpu` makes the
//! transmittance, multiple-scattering and sky-irradiance tables and the display's daylight
//! balance once, when the pass is built (they depend on the air alone, which a renderer's
//! settings fix), and each frame the sky-view table from the camera's altitude and the sun and the
//! aerial-perspective volume over the view's frustum, then draws the sky where the depth target
//! still holds the far plane. `gpu::air` is what the ground, the seeds and the texcells bind to be lit
//! by the sun and the sky through the air and seen through it. The twin is
//! `reference::atmosphere`; the brute-force model judges both (`atmosphere::brute`,
//! `docs/atmosphere.md`).

pub mod frame;
pub mod gpu;
