//! Pass 4's CPU half: the impostors of a class table's species, read from a folder, and the
//! frame's constants.

use std::path::Path;

use crate::classes::Species;
use crate::config::Settings;
use crate::gpu::gpu_types::{DrawSeedsUniforms, TerrainUniforms};
use crate::impostor::{Impostor, MANIFEST_FILE};
use crate::seeds::wind::WindFrame;

use super::DrawSeedsError;

/// How much of the ground colour under a seed it takes on.
pub const GROUND_BLEND: f32 = 0.2;

/// Each species' impostor (index = species index of the class table), `None` where the folder has
/// no model of that name.
pub fn load_impostors(dir: &Path, species: &[Species]) -> Result<Vec<Option<Impostor>>, DrawSeedsError> {
    if !dir.is_dir() {
        return Err(DrawSeedsError::NoFolder(dir.to_path_buf()));
    }
    let mut loaded: Vec<Option<Impostor>> = Vec::with_capacity(species.len());
    for s in species {
        let known = loaded.iter().flatten().find(|i| i.name == s.model).cloned();
        let impostor = match known {
            Some(impostor) => Some(impostor),
            None if dir.join(&s.model).join(MANIFEST_FILE).is_file() => {
                Some(crate::impostor::load(dir, &s.model)?)
            }
            None => None,
        };
        loaded.push(impostor);
    }
    Ok(loaded)
}

/// The frame's constants from the settings, the terrain's matrix, sun and haze, and the wind.
pub fn draw_uniforms(settings: &Settings, terrain: &TerrainUniforms, wind: &WindFrame) -> DrawSeedsUniforms {
    DrawSeedsUniforms {
        clip_from_view_world: terrain.clip_from_view_world,
        sun_dir: terrain.sun_dir,
        haze: terrain.haze,
        draw_reach_m: settings.draw_seeds.reach_m.map(|r| r as f32),
        inv_reference_height_m: (1.0 / settings.seeds.reference_height_m) as f32,
        sink_fraction: settings.seeds.sink_fraction as f32,
        fade_fraction: settings.draw_seeds.fade_fraction as f32,
        ground_blend: GROUND_BLEND,
        wind: wind.wind,
        wind_wave: wind.wave,
    }
}
