//! The Earth mapping's structs (`earth::local`, `shaders/shared/earth.wgsl`).

use bytemuck::{Pod, Zeroable};

use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// A node's mapping into the camera's local frame (`earth::local::NodeMapping`, xyz; w unused):
    /// its origin's camera-relative position, metres, and the mapping's derivatives there. WGSL:
    /// `EarthNode` in `shaders/shared/earth.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct EarthNode {
        /// The origin's position.
        pub origin_m: [f32; 4],
        /// ∂p/∂x, per metre of CRS offset.
        pub d_x: [f32; 4],
        /// ∂p/∂y.
        pub d_y: [f32; 4],
        /// ∂p/∂h, per metre of height.
        pub d_h: [f32; 4],
        /// ½ ∂²p/∂x², per square metre.
        pub d_xx: [f32; 4],
        /// ∂²p/∂x∂y.
        pub d_xy: [f32; 4],
        /// ½ ∂²p/∂y².
        pub d_yy: [f32; 4],
        /// ∂²p/∂x∂h.
        pub d_xh: [f32; 4],
        /// ∂²p/∂y∂h.
        pub d_yh: [f32; 4],
    }
}

impl EarthNode {
    /// The flat sheet's mapping with its origin at the camera: the identity (first derivatives
    /// the axes, no second ones).
    pub const FLAT: Self = Self {
        origin_m: [0.0; 4],
        d_x: [1.0, 0.0, 0.0, 0.0],
        d_y: [0.0, 1.0, 0.0, 0.0],
        d_h: [0.0, 0.0, 1.0, 0.0],
        d_xx: [0.0; 4],
        d_xy: [0.0; 4],
        d_yy: [0.0; 4],
        d_xh: [0.0; 4],
        d_yh: [0.0; 4],
    };
}

gpu_struct! {
    /// A point the mapping's probe places (`earth::gpu::probe_positions`): its CRS offset from its
    /// node's origin and its height above it (xyz, metres), and the node's index. WGSL:
    /// `EarthProbePoint` in `shaders/earth.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct EarthProbePoint {
        /// Offset from the node's origin.
        pub offset_m: [f32; 3],
        /// Index of the node in the probe's node array.
        pub node: u32,
    }
}
