//! Pass 4's CPU half: the impostors of a class table's species, read from a folder, the frame's
//! constants, and the frame's index range of each mesh drawn with continuous LOD: LOD 1's seeds
//! are at least `draw_seeds.reach_m[0]` away (scaled by their size, as pass 3 assigns them), so
//! the leaves that the nearest of them could keep bound the range (stems stay in it: some seed
//! may draw them, widened); each seed then sheds what it does not need in the vertex shader.

use std::path::Path;

use crate::classes::Species;
use crate::config::Settings;
use crate::gpu::gpu_types::{DrawSeedsUniforms, EarthNode, SeedDrawArgs, TerrainUniforms};
use crate::gpu::layout::{SEED_GROUPS, SEED_LODS};
use crate::impostor::detail::{first_leaf_kept, leaf_share, projected_px};
use crate::impostor::{Impostor, MANIFEST_FILE};
use crate::seeds::wind::WindFrame;

use super::DrawSeedsError;
use super::assets::MeshDetail;

/// How much nearer than its LOD's reach a seed of LOD 1 may be found when the frame's range is
/// bounded: pass 3 and the draw measure the same distance in f32, a few ulps apart.
const NEAREST_MARGIN: f32 = 0.98;

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
            None if has_impostor(dir, &s.model) => Some(crate::impostor::load(dir, &s.model)?),
            None => None,
        };
        loaded.push(impostor);
    }
    Ok(loaded)
}

/// Whether `dir` holds an impostor of `model` (its manifest): the species of that model are drawn.
pub fn has_impostor(dir: &Path, model: &str) -> bool {
    dir.join(model).join(MANIFEST_FILE).is_file()
}

/// The frame's constants from the settings, the terrain's matrix, sun and clouds, the
/// wind, and `earth`, the mapping pass 3 stood the seeds with (`SeedUniforms::earth`).
pub fn draw_uniforms(
    settings: &Settings,
    terrain: &TerrainUniforms,
    wind: &WindFrame,
    earth: &EarthNode,
) -> DrawSeedsUniforms {
    DrawSeedsUniforms {
        clip_from_view_world: terrain.clip_from_view_world,
        sun_dir: terrain.sun_dir,
        draw_reach_m: settings.draw_seeds.reach_m.map(|r| r as f32),
        inv_reference_height_m: (1.0 / settings.seeds.reference_height_m) as f32,
        sink_fraction: settings.seeds.sink_fraction as f32,
        fade_fraction: settings.draw_seeds.fade_fraction as f32,
        wind: wind.wind,
        wind_wave: wind.wave,
        cloud_field: terrain.cloud_field,
        cloud_shift: terrain.cloud_shift,
        seed_up: earth.d_h,
        seed_up_per_x_m: earth.d_xh,
        seed_up_per_y_m: earth.d_yh,
        // The pass fills it in from its geometry (`DrawSeedsPass::prepare`).
        from_above: [[0.0; 4]; SEED_GROUPS as usize],
        focal_px: focal_px(terrain, settings.render.height),
        continuous_lod: settings.draw_seeds.continuous_lod.into(),
        prefilter_small: settings.draw_seeds.prefilter_small.into(),
        _pad: [0; 2],
    }
}

/// The focal length, pixels, of a view `height_px` tall drawn with `terrain`'s matrix: its
/// projection's vertical scale (the length of the matrix's second row, the view's rotation
/// leaving it unchanged) times half the height.
pub fn focal_px(terrain: &TerrainUniforms, height_px: u32) -> f32 {
    let m = terrain.clip_from_view_world;
    let row_y = glam::Vec3::new(m[0][1], m[1][1], m[2][1]);
    0.5 * height_px as f32 * row_y.length()
}

/// Each draw's index range for this frame (`templates` as built, `SEED_DRAWS`), the LOD 1 draw of
/// each species in `details` narrowed to what its nearest possible seed keeps: seeds at least
/// `reach_m[0]` away scaled by their size (`seeds.reference_height_m` and taller: all of it), up
/// to each species' `tallest_m`, its model `inv_model_height_m` per metre tall.
pub fn detail_templates(
    templates: &[SeedDrawArgs],
    details: &[Option<MeshDetail>],
    tallest_m: &[f32],
    inv_model_height_m: &[f32],
    settings: &Settings,
    focal_px: f32,
) -> Vec<SeedDrawArgs> {
    let mut out = templates.to_vec();
    let reach_m = (settings.draw_seeds.reach_m[0] as f32 * NEAREST_MARGIN).max(1e-3);
    let reference_m = settings.seeds.reference_height_m as f32;
    for (s, detail) in details.iter().enumerate() {
        let (Some(detail), Some(&tallest_m)) = (detail, tallest_m.get(s)) else { continue };
        // The seed that projects largest in LOD 1: the tallest at the reach, a smaller one at its
        // own shorter reach, all alike below the reference height.
        let scale = tallest_m.max(reference_m) * inv_model_height_m.get(s).copied().unwrap_or(0.0);
        let px = |size_m: f32| projected_px(size_m, scale, focal_px, reach_m);
        let mut start = u32::MAX;
        let mut end = 0;
        if let Some(leaves) = detail.leaves {
            let first = first_leaf_kept(leaves.count, leaf_share(px(leaves.size_m)).0);
            if first < leaves.count {
                start = leaves.first_index + 6 * first;
                end = leaves.first_index + 6 * leaves.count;
            }
        }
        // Stems, however thin, are drawn widened on some seeds.
        let stems = detail.stems.iter().map(|(range, _)| range);
        for range in stems.chain(&detail.whole_pieces).filter(|r| !r.is_empty()) {
            (start, end) = (start.min(range.start), end.max(range.end));
        }
        let lod1 = &mut out[s * SEED_LODS as usize + 1];
        (lod1.first_index, lod1.index_count) =
            if start < end { (start, end - start) } else { (detail.whole.first_index, 0) };
    }
    out
}
