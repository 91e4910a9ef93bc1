//! The seed draw's structs (pass 4b): per-frame constants, materials and vertices.

use bytemuck::{Pod, Zeroable};

use crate::gpu::layout::SEED_GROUPS;
use crate::gpu::struct_layout::gpu_struct;

gpu_struct! {
    /// Per-frame constants of the seed-drawing pass. WGSL: `DrawSeedsUniforms` in
    /// `shaders/draw_seeds.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
    pub struct DrawSeedsUniforms {
        /// The terrain's: clip space from camera-relative world space.
        pub clip_from_view_world: [[f32; 4]; 4],
        /// Unit vector towards the sun, w unused.
        pub sun_dir: [f32; 4],
        /// Each draw LOD's reach (`draw_seeds.reach_m`), metres, scaled by each seed's size.
        pub draw_reach_m: [f32; 4],
        /// 1 / the seed height that gets the full reaches, 1/m: a smaller seed's reach shrinks with
        /// its height.
        pub inv_reference_height_m: f32,
        /// Fraction of its height a seed's anchor was sunk by (pass 3's), undone to measure its
        /// distance.
        pub sink_fraction: f32,
        /// The outer part of each LOD band over which a seed dithers out, as a fraction of its reach.
        pub fade_fraction: f32,
        /// The lens's focal length, pixels: what a metre one metre away covers on screen.
        pub focal_px: f32,
        /// The wind (`seeds::wind::WindFrame::wind`): downwind unit vector (xy), a top's mean lean
        /// and sway per metre of height (zw); lean 0: still air, no vertex moves.
        pub wind: [f32; 4],
        /// Wind time, seconds (x), the gusts' wavenumber per metre (y) and phase at the camera (z).
        pub wind_wave: [f32; 4],
        /// The terrain's cloud shadows (`TerrainUniforms::cloud_field`, `cloud_shift`).
        pub cloud_field: [f32; 4],
        /// See `cloud_field`.
        pub cloud_shift: [f32; 4],
        /// The local vertical at the camera's nadir (xyz; w unused), and how it turns per metre
        /// east (`seed_up_per_x_m`) and north (`seed_up_per_y_m`): pass 3's mapping's ∂p/∂h and
        /// its derivatives (`SeedUniforms::earth`). A seed stands along the vertical at its
        /// place; straight up (0, 0, 1) and no turn on the flat sheet.
        pub seed_up: [f32; 4],
        /// See `seed_up`.
        pub seed_up_per_x_m: [f32; 4],
        /// See `seed_up`.
        pub seed_up_per_y_m: [f32; 4],
        /// 1: meshes that say how shed detail as they shrink on screen (`impostor::detail`,
        /// `draw_seeds.continuous_lod`); 0: they do not.
        pub continuous_lod: u32,
        /// 1: a seed a few pixels tall shows its mean colour seen from above (`SEED_DETAIL_*`,
        /// `draw_seeds.prefilter_small`); 0: always its own detail (the truth, which supersamples).
        pub prefilter_small: u32,
        /// Padding to the WGSL struct's alignment (always 0).
        pub _pad: [u32; 2],
        /// The colour follow-up's yardstick, per (species, draw LOD) group
        /// (`species · SEED_LODS + lod`): the group's foliage seen from above
        /// (`draw_seeds::from_above`), its mean albedo (xyz) and its mean facing towards this
        /// frame's sun (w), from which the shader scales it to the photograph under the light at
        /// each seed (`photo_scale_at`); 0: the model keeps its colours.
        pub from_above: [[f32; 4]; SEED_GROUPS as usize],
    }
}

gpu_struct! {
    /// What pass 4 knows of a species besides its geometry. WGSL: `SeedShape`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedShape {
        /// 1 / the model's height (top above base), per metre; 0 for species not drawn.
        pub inv_model_height_m: f32,
        /// How much the wind bends it (`seeds::wind::bend_of`): 1 a plant, 0 a rock.
        pub wind_bend: f32,
        /// How much its foliage follows the photograph's colour under it
        /// (`classes::Species::ground_blend`): 1 the photograph's local mean, 0 its own colours.
        pub ground_blend: f32,
        /// How much darker it is low in its crown and away from the sun
        /// (`classes::Species::crown_shading`).
        pub crown_shading: f32,
    }
}

gpu_struct! {
    /// How a seed vertex is coloured: a base colour times (when `flags` has `MATERIAL_TEXTURED`) a
    /// layer of the seed texture array, alpha-tested; the draw LODs of the geometry it belongs to
    /// (0 the mesh, 1 to 3 the billboard clouds), which tell a group's own draw from its
    /// cross-fade; how its primitives shed detail (`MATERIAL_LEAVES`, `MATERIAL_STEMS`); whether
    /// it is bark (`MATERIAL_BARK`) or a slicing's slices (`MATERIAL_SLICE`).
    /// WGSL: `SeedMaterial` in `shaders/draw_seeds.wgsl`.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedMaterial {
        /// Linear RGBA, multiplied with the texel.
        pub base_colour: [f32; 4],
        /// Layer of the seed texture array it samples (with `MATERIAL_TEXTURED`).
        pub layer: u32,
        /// Fragments with alpha below this are cut out (below 0: opaque).
        pub alpha_cutoff: f32,
        /// First draw LOD its geometry serves: a draw whose seeds are of a LOD outside `lod` to
        /// `last_lod` is their cross-fade.
        pub lod: u32,
        /// `MATERIAL_TEXTURED` | `MATERIAL_REPEAT` (wrap texture coordinates, else clamp) |
        /// `MATERIAL_LEAVES` or `MATERIAL_STEMS` (continuous LOD).
        pub flags: u32,
        /// Last draw LOD its geometry serves: `lod`, but for a mesh drawn with continuous LOD,
        /// which also takes the place of the 17-plane cloud.
        pub last_lod: u32,
        /// `MATERIAL_LEAVES`: the leaves' mean size; `MATERIAL_STEMS`: the stems' mean diameter;
        /// model metres.
        pub detail_m: f32,
        /// `MATERIAL_LEAVES`: the vertex (in the pass's vertex buffer) where its leaf quads start,
        /// four vertices each, in the order they thin out.
        pub first_leaf_vertex: u32,
        /// `MATERIAL_LEAVES`: how many leaf quads it has.
        pub leaf_count: u32,
        /// `MATERIAL_SLICE`: how many slicings its slices belong to, evenly spread around the
        /// vertical (`impostor::slicing::orientation`); a slice's own is its normal's.
        pub slicings: u32,
        /// `MATERIAL_SLICE`: the brightness correction's multiplier (`draw_seeds.slicing_brightness`).
        pub slicing_brightness: f32,
        /// Padding to the struct's 16-byte alignment.
        pub _pad: [u32; 2],
    }
}

gpu_struct! {
    /// A vertex of a seed's mesh or billboard cloud, model space (metres, +Y up, base at y = 0), as
    /// the draw pass uploads it; `material` indexes its `SeedMaterial` table.
    #[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq, Default)]
    pub struct SeedVertex {
        /// Position, model space, metres; scaled to the seed's height when drawn.
        pub position_model_m: [f32; 3],
        /// Unit normal, model space.
        pub normal_model: [f32; 3],
        /// Texture coordinates in its material's layer (wrapped or clamped per `MATERIAL_REPEAT`).
        pub uv: [f32; 2],
        /// Index into the draw pass's `SeedMaterial` table.
        pub material: u32,
        /// Where the vertex's leaf hangs, model space (`MeshVertex::pivot_model_m`): the wind turns
        /// the leaf about it; the vertex itself where nothing flutters (bark, billboard clouds).
        pub pivot_model_m: [f32; 3],
    }
}
