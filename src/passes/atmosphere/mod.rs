//! The atmosphere pass (Hillaire 2020; the model is `atmosphere`): the air's look-up tables made
//! by compute, and the sky drawn from them behind everything the frame holds.
//!
//! How it works: `frame` turns the `[atmosphere]` settings and the view (its camera-relative
//! rays, its zenith, its altitude, the sun) into `AtmosphereUniforms`. `gpu` makes the
//! transmittance and multiple-scattering tables once, when the pass is built (they depend on the
//! air alone, which a renderer's settings fix), and each frame the sky-view table from the
//! camera's altitude and the sun, then draws the sky where the depth target still holds the far
//! plane. The twin is `reference::atmosphere`; the brute-force model judges both
//! (`atmosphere::brute`, `docs/atmosphere.md`).

pub mod frame;
pub mod gpu;
