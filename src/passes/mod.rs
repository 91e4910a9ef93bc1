//! How it works: one folder per GPU pass of the frame, each with its shader of the same name in
//! `shaders/` and, for the passes whose output the CPU relies on, a CPU twin of the same name in
//! `reference/`. A pass folder holds a `frame` half (plain CPU data the pass consumes and produces:
//! layouts, frame inputs, cell lists, Hi-Z mips, compaction results), which the twins and the
//! renderer's CPU work may import, and a `gpu` half (pipelines and binding tables built once in
//! `new`, per-frame uploads in `prepare`, commands recorded in `encode`). `frame::Renderer` calls
//! them in the order of the paper's passes:
//!
//! 0. `terrain` (+ `depth_pyramid`): the ground's depth, and its Hi-Z pyramid;
//! 1. `tile_load_map`: which tiles and seed patterns the view needs, read back a frame late;
//! 2. `ground`: imagery on the terrain, from the finest resident level, and `texcells`: the far
//!    forest over it, where the land cover is dense;
//! 3. `seed_select`: the seeds of the visible near cells, culled and classified;
//! 4. `compact` and `draw_seeds`: the survivors grouped into indirect draws, and drawn;
//!
//! then `display`: the frame's light, exposed and through a tone curve, as the screen shows it.

pub mod atmosphere;
pub mod compact;
pub mod depth_pyramid;
pub mod display;
pub mod draw_seeds;
pub mod ground;
pub mod limits;
pub mod seed_select;
pub mod terrain;
pub mod texcells;
pub mod tile_load_map;

use crate::gpu::bindings::PipelineBindings;
use crate::gpu::shaders::WgslSource;

/// The colour target every pass that shades draws into: light balanced for daylight (1 is white
/// ground in daylight; `passes::display`), in floating point so the sun, snow and dusk keep their
/// stops until the display exposes them.
pub const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The display target the display pass writes, what is saved and shown (sRGB: the hardware
/// encodes on store).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// A host's linear HDR colour target, which takes the light exposed and through no tone curve,
/// for the host's own (`frame::HostTargets`): half floats, blendable on every adapter.
pub const HOST_HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The depth target: reversed-Z (1 at the near plane, 0 at infinity), written by the terrain.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Every pass's shader, in frame order, then the Earth mapping's probe (`earth::gpu`).
pub const SHADERS: &[&WgslSource] = &[
    &terrain::gpu::SHADER,
    &depth_pyramid::gpu::SHADER,
    &tile_load_map::gpu::SHADER,
    &ground::gpu::SHADER,
    &texcells::gpu::SHADER,
    &seed_select::gpu::SHADER,
    &compact::gpu::SHADER,
    &draw_seeds::gpu::SHADER,
    &crate::earth::gpu::SHADER,
    &atmosphere::gpu::SHADER,
    &display::gpu::SHADER,
];

/// Every pipeline's bind group and the shader entry points it serves: what the binding-table test
/// checks against the WGSL.
pub const PIPELINE_BINDINGS: &[PipelineBindings] = &[
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["transmittance_lut"],
        group: 0,
        bindings: &atmosphere::gpu::TRANSMITTANCE_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["multiple_scattering_lut"],
        group: 0,
        bindings: &atmosphere::gpu::MULTIPLE_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["sky_view_lut"],
        group: 0,
        bindings: &atmosphere::gpu::SKY_VIEW_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["aerial_perspective_lut"],
        group: 0,
        bindings: &atmosphere::gpu::AERIAL_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["irradiance_lut"],
        group: 0,
        bindings: &atmosphere::gpu::IRRADIANCE_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["daylight_balance"],
        group: 0,
        bindings: &atmosphere::gpu::DAYLIGHT_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["vs_sky", "fs_sky"],
        group: 0,
        bindings: &atmosphere::gpu::SKY_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &atmosphere::gpu::SHADER,
        entry_points: &["vs_sky", "fs_sky_marched"],
        group: 0,
        bindings: &atmosphere::gpu::SKY_MARCHED_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &display::gpu::SHADER,
        entry_points: &["vs_display", "fs_display", "fs_display_over"],
        group: 0,
        bindings: &display::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &crate::earth::gpu::SHADER,
        entry_points: &["probe_earth_positions", "probe_earth_stand"],
        group: 0,
        bindings: &crate::earth::gpu::PROBE_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &terrain::gpu::SHADER,
        entry_points: &["vs_main"],
        group: 0,
        bindings: &terrain::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &depth_pyramid::gpu::SHADER,
        entry_points: &["reduce_depth"],
        group: 0,
        bindings: &depth_pyramid::gpu::FROM_DEPTH.bindings,
    },
    PipelineBindings {
        shader: &depth_pyramid::gpu::SHADER,
        entry_points: &["reduce_mip"],
        group: 0,
        bindings: &depth_pyramid::gpu::FROM_MIP.bindings,
    },
    PipelineBindings {
        shader: &tile_load_map::gpu::SHADER,
        entry_points: &["main"],
        group: 0,
        bindings: &tile_load_map::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &ground::gpu::SHADER,
        entry_points: &["vs_main", "fs_main"],
        group: 0,
        bindings: &terrain::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &texcells::gpu::SHADER,
        entry_points: &["vs_texcell", "fs_texcell"],
        group: 0,
        bindings: &terrain::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &texcells::gpu::SHADER,
        entry_points: &["vs_texcell", "fs_texcell"],
        group: 1,
        bindings: &texcells::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &texcells::gpu::SHADER,
        entry_points: &["probe_forest_uv"],
        group: 1,
        bindings: &texcells::gpu::probe::PROBE_UNIFORMS.bindings,
    },
    PipelineBindings {
        shader: &texcells::gpu::SHADER,
        entry_points: &["probe_forest_uv"],
        group: 2,
        bindings: &texcells::gpu::probe::PROBE_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &seed_select::gpu::SHADER,
        entry_points: &["main", "settle"],
        group: 0,
        bindings: &seed_select::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &seed_select::gpu::SHADER,
        entry_points: &["settle"],
        group: 1,
        bindings: &seed_select::gpu::SETTLE_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &compact::gpu::SHADER,
        entry_points: &["reduce", "scan", "finish", "scatter"],
        group: 0,
        bindings: &compact::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &draw_seeds::gpu::SHADER,
        entry_points: &["vs_main", "fs_main", "fs_coverage", "fs_truth"],
        group: 0,
        bindings: &draw_seeds::gpu::BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &ground::gpu::SHADER,
        entry_points: &["vs_main", "fs_main"],
        group: atmosphere::gpu::air::AIR_GROUP,
        bindings: &atmosphere::gpu::air::AIR_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &texcells::gpu::SHADER,
        entry_points: &["vs_texcell", "fs_texcell"],
        group: atmosphere::gpu::air::AIR_GROUP,
        bindings: &atmosphere::gpu::air::AIR_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &draw_seeds::gpu::SHADER,
        entry_points: &["vs_main", "fs_main", "fs_coverage", "fs_shade_samples", "fs_truth"],
        group: atmosphere::gpu::air::AIR_GROUP,
        bindings: &atmosphere::gpu::air::AIR_BINDINGS.bindings,
    },
    PipelineBindings {
        shader: &draw_seeds::gpu::SHADER,
        entry_points: &["vs_fill", "fs_fill"],
        group: 0,
        bindings: &draw_seeds::gpu::multisample::FILL_BINDINGS.bindings,
    },
];
