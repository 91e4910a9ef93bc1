//! The rows of `docs/PRESETS.md`'s knob table: each knob's cell and the settings that fill it
//! under each preset.

use super::claims::{PresetRow, auto_zero, mib, on_off, plain, signed};

pub static PRESET_ROWS: &[PresetRow] = &[
    PresetRow { knob: "`terrain.triangle_px`", cell: "{}", keys: &[("terrain.triangle_px", plain)] },
    PresetRow { knob: "`terrain.morph_fraction`", cell: "{}", keys: &[("terrain.morph_fraction", plain)] },
    PresetRow { knob: "`imagery.lod_bias`", cell: "{}", keys: &[("imagery.lod_bias", signed)] },
    PresetRow { knob: "`imagery.anisotropy`", cell: "{}", keys: &[("imagery.anisotropy", auto_zero)] },
    PresetRow {
        knob: "`cache.height_slots` / `imagery_slots`",
        cell: "{} / {}",
        keys: &[("cache.height_slots", plain), ("cache.imagery_slots", plain)],
    },
    PresetRow {
        knob: "`cache.upload_tiles_per_frame` / `bytes`",
        cell: "{} / {} MiB",
        keys: &[("cache.upload_tiles_per_frame", plain), ("cache.upload_bytes_per_frame", mib)],
    },
    PresetRow { knob: "`tlm.cells`", cell: "{}", keys: &[("tlm.cells", plain)] },
    PresetRow { knob: "`tlm.radial_bands_m`", cell: "{} / {} / {}", keys: &[("tlm.radial_bands_m", plain)] },
    PresetRow {
        knob: "`draw_seeds.reach_m`",
        cell: "{} / {} / {} / {}",
        keys: &[("draw_seeds.reach_m", plain)],
    },
    PresetRow {
        knob: "`draw_seeds.fade_fraction`",
        cell: "{}",
        keys: &[("draw_seeds.fade_fraction", plain)],
    },
    PresetRow { knob: "`draw_seeds.samples`", cell: "{}", keys: &[("draw_seeds.samples", plain)] },
    PresetRow {
        knob: "`draw_seeds.continuous_lod`",
        cell: "{}",
        keys: &[("draw_seeds.continuous_lod", on_off)],
    },
    PresetRow { knob: "`draw_seeds.slicings`", cell: "{}", keys: &[("draw_seeds.slicings", on_off)] },
    PresetRow { knob: "`texcells.reach_m`", cell: "{}", keys: &[("texcells.reach_m", plain)] },
    PresetRow { knob: "`texcells.slice_px`", cell: "{}", keys: &[("texcells.slice_px", plain)] },
    PresetRow { knob: "`texcells.silhouette_deg`", cell: "{}", keys: &[("texcells.silhouette_deg", plain)] },
    PresetRow {
        knob: "`texcells.silhouette_steps`",
        cell: "{}",
        keys: &[("texcells.silhouette_steps", plain)],
    },
    PresetRow { knob: "`seeds.seeds_per_pattern`", cell: "{}", keys: &[("seeds.seeds_per_pattern", plain)] },
    PresetRow { knob: "`seeds.density_scale`", cell: "{}", keys: &[("seeds.density_scale", plain)] },
    PresetRow {
        knob: "`seeds.reference_height_m`",
        cell: "{}",
        keys: &[("seeds.reference_height_m", plain)],
    },
    PresetRow { knob: "`seeds.frustum_epsilon`", cell: "{}", keys: &[("seeds.frustum_epsilon", plain)] },
    PresetRow {
        knob: "`seeds.occlusion_tolerance_m` / `_per_km`",
        cell: "{} / {}",
        keys: &[("seeds.occlusion_tolerance_m", plain), ("seeds.occlusion_tolerance_per_km", plain)],
    },
    PresetRow {
        knob: "`seeds.occlusion_refine_steps`",
        cell: "{}",
        keys: &[("seeds.occlusion_refine_steps", plain)],
    },
    PresetRow {
        knob: "`render.width` × `height`",
        cell: "{} × {}",
        keys: &[("render.width", plain), ("render.height", plain)],
    },
];
