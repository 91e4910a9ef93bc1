//! The atmosphere pass's struct (`passes::atmosphere`, `shaders/shared/atmosphere.wgsl`).

use bytemuck::{Pod, Zeroable};

use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// The atmosphere's model, the view the sky is seen from, and its tables' sizes. Lengths in
    /// km. WGSL: `AtmosphereUniforms` in `shaders/shared/atmosphere.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct AtmosphereUniforms {
        /// Rayleigh scattering at the ground per km (xyz), its scale height (w).
        pub rayleigh: [f32; 4],
        /// Mie scattering (x) and extinction (y) at the ground per km, scale height (z), g (w).
        pub mie: [f32; 4],
        /// The phase functions' Legendre moments (`atmosphere::legendre_moments`): Rayleigh's
        /// k₂ (x), the aerosols' k₁ and k₂ (y, z); unused (w).
        pub phase_moments: [f32; 4],
        /// Ozone absorption at its peak per km (xyz), the peak's altitude (w).
        pub ozone: [f32; 4],
        /// The ground's albedo (xyz), the ozone tent's half width (w).
        pub albedo: [f32; 4],
        /// Radius of the ground (x) and of the top of the air (y); the view's radius for the
        /// sky-view table, within the air (z); the cosine of the sun's zenith there (w).
        pub radii: [f32; 4],
        /// Camera-relative world from clip space: the sky's view rays.
        pub view_world_from_clip: [[f32; 4]; 4],
        /// Its inverse: where a point of the lit passes lies on the aerial-perspective volume's
        /// tiles.
        pub clip_from_view_world: [[f32; 4]; 4],
        /// The view's zenith in camera-relative world space (xyz), its radius, km, wherever it
        /// is (w; `radii.z` holds it within the air).
        pub up: [f32; 4],
        /// Unit vector towards the sun in that space (xyz), the sun's angular radius (w).
        pub sun_dir: [f32; 4],
        /// The transmittance table's width and height, texels.
        pub transmittance_size: [u32; 2],
        /// The multiple-scattering table's.
        pub multiple_size: [u32; 2],
        /// The sky-view table's.
        pub sky_view_size: [u32; 2],
        /// The aerial-perspective volume's tiles across and down the screen.
        pub aerial_size: [u32; 2],
        /// How far its last slice reaches from the camera, km.
        pub aerial_far_km: f32,
        /// Its slices.
        pub aerial_slices: u32,
        /// 1 where the ground, the seeds and the texcells are seen through the air (aerial
        /// perspective), 0 where the air is left out between them and the camera.
        pub aerial_on: u32,
        /// Unused, to the struct's 16-byte alignment.
        pub _pad: u32,

    }
}
