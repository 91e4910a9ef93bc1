//! The display pass's struct (`passes::display`, `shaders/display.wgsl`).

use bytemuck::{Pod, Zeroable};

use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// The exposure and the tone curve the frame is shown through (`passes::display::uniforms`).
    /// WGSL: `DisplayUniforms` in `shaders/display.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct DisplayUniforms {
        /// The curve's matrix into its own primaries, row by row (xyz; w unused).
        pub into_curve: [[f32; 4]; 3],
        /// Its matrix back to the display's, row by row, applied after the curve.
        pub out_of_curve: [[f32; 4]; 3],
        /// The curve's coefficients: AgX's polynomial, lowest power first (seven); ACES's
        /// rational fit (five).
        pub coefficients: [[f32; 4]; 2],
        /// AgX's log encoding: the least and the most log2 of light it spans (x, y); the power
        /// that takes its output to linear light (z); unused (w).
        pub encoding: [f32; 4],
        /// The luminance of linear sRGB (Rec. 709 weights, xyz; w unused).
        pub luminance: [f32; 4],
        /// The exposure of a radiance times π of 1 (in units of the sun's irradiance above the
        /// air): the sun's illuminance over π, in cd/m², over the saturation-based exposure's
        /// 1.2 × 2^EV100 (x; yzw unused).
        pub exposure: [f32; 4],
    }
}
