// The atmosphere's constants (`atmosphere`, `passes::atmosphere`, `reference::atmosphere`): the
// tables' quadratures and the frame's light range. Included into `gpu::layout` (`include!`), so
// its block is one of the module's own and imports nothing.

wgsl_constants! { atmosphere_constants:
    /// π in f32, for the phase functions and the sky's angles.
    pub const PI: f32 = std::f32::consts::PI;
    /// Texels per side of a workgroup of the atmosphere's tables.
    pub const ATMOSPHERE_WORKGROUP: u32 = 8;
    /// Segments of the quadrature from a point to the top of the air (the transmittance table).
    pub const TRANSMITTANCE_STEPS: u32 = 40;
    /// Directions per side of the grid the multiple-scattering table gathers over (16 × 16 =
    /// 256 over the sphere; Hillaire's 64 leave the light about the horizon too coarse for the
    /// table's expansion in the view direction: docs/atmosphere.md).
    pub const MULTIPLE_DIRECTIONS_SIDE: u32 = 16;
    /// Terms of the multiple-scattering table's expansion in the view direction: the real
    /// spherical harmonics up to degree 2 that are even across the sun's vertical plane
    /// (1, z, x, 3z² − 1, xz, x² − y² in the frame whose x points to the sun's azimuth).
    pub const MULTIPLE_TERMS: u32 = 6;
    /// Segments along each of those directions.
    pub const MULTIPLE_STEPS: u32 = 20;
    /// Segments along a view ray of the sky-view table (and of the sky marched per pixel).
    pub const SKY_VIEW_STEPS: u32 = 30;
    /// Views higher than this above the ground, km, march the sky per pixel: from there the
    /// limb's rows of the sky-view table span more than the air's scale height (docs/atmosphere.md).
    pub const SKY_MARCHED_ABOVE_KM: f32 = 30.0;
    /// Segments per slice of the aerial-perspective volume.
    pub const AERIAL_SUBSTEPS: u32 = 4;
    /// Directions per side of the grid the sky-irradiance table gathers over (8 × 8 = 64 over
    /// the upper hemisphere).
    pub const IRRADIANCE_DIRECTIONS_SIDE: u32 = 8;
    /// The sun's zenith cosine of the daylight the frame's light is balanced for (45°): level
    /// white ground at sea level under it, sun and sky, is 1 (`daylight_balance`).
    pub const DAYLIGHT_SUN_COS: f32 = 0.70710677;
    /// The most balanced light a pass writes (`balanced`): the colour target's f16 holds up to
    /// 65,504, and the sun's disk above the air is about 72,000 times white ground (its
    /// irradiance over its solid angle, 1 / (π 0.004675²), times π and the daylight balance).
    pub const SCENE_LIGHT_MAX: f32 = 60000.0;
    /// The most exposed light the display writes over a host's linear HDR colour: f16's largest,
    /// so that an exposure low enough to take the sun's disk past it leaves the host a bright
    /// pixel, not infinity.
    pub const HOST_HDR_MAX: f32 = 65504.0;
}
