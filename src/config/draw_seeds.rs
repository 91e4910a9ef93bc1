//! How it works: the `[draw_seeds]` table: how far each draw LOD reaches (pass 3 assigns them,
//! pass 4 draws them), the cross-fade between them, and the impostors pass 4 draws with;
//! range-checked like the rest of the settings. See `config/default.toml` for what each buys.

use serde::Deserialize;

use super::{RangeCheck, SettingsError, TlmSettings, first_out_of_range};
use crate::gpu::layout::{SEED_LODS, SEED_SAMPLES};

/// Drawing the seeds, see `config/default.toml` `[draw_seeds]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrawSeedsSettings {
    /// How far each draw LOD reaches for a seed of `seeds.reference_height_m` or taller (smaller
    /// seeds in proportion), metres: the real mesh, then the billboard clouds of 17, 8 and 2
    /// planes. Beyond the last a seed is not drawn.
    pub reach_m: [f64; SEED_LODS as usize],
    /// The outer part of each LOD's reach over which a seed cross-fades into the next LOD (the
    /// last LOD: fades out), as a fraction of the reach; 0 switches at once (pops).
    pub fade_fraction: f64,
    /// Samples per pixel the seeds are drawn with: 1 alpha-tests every fragment at the pixel's
    /// centre; `SEED_SAMPLES` (4) draws them multisampled, each fragment covering as many of its
    /// pixel's samples as its (sharpened) alpha says, and resolves into the frame.
    pub samples: u32,
    /// Every draw first writes the depth of what it keeps (alpha test and dithers only), then is
    /// repeated testing depth for equality, so only the fragment each sample shows is lit.
    pub depth_prepass: bool,
    /// Meshes whose materials say how they shed detail (generated trees) are drawn with continuous
    /// LOD (Wesslén & Seipel, `impostor::detail`): leaves thin out and sub-pixel stems are drawn
    /// a pixel wide on a share of the seeds as they shrink on screen, and the thinned mesh also
    /// takes the 17-plane cloud's place (LOD 1).
    pub continuous_lod: bool,
    /// A seed a few pixels tall seen from above shows its mean colour seen from above (the
    /// photograph's under it, where it follows the photograph) instead of one sample of its
    /// shading and gaps a pixel (`SEED_DETAIL_*`, `small_seed_mean` in `shaders/draw_seeds.wgsl`).
    pub prefilter_small: bool,
    /// Species whose impostor carries slicings (`terramp-data bake --slicings`) draw them in
    /// LOD 1's place (Jakulin 2000): the mesh's trunk and limbs, and the crown's two slicings
    /// nearest the view, blended.
    pub slicings: bool,
    /// The slicings' brightness correction's multiplier (the paper's m_s): both blended slicings'
    /// opacities are raised by 1 + this × the secondary's share.
    pub slicing_brightness: f64,
    /// Folder of baked impostors (`terramp-data bake`), one sub-folder per model; "" = seeds are
    /// selected but not drawn. Species whose model is not there are not drawn.
    pub impostors: String,
}

impl DrawSeedsSettings {
    pub(super) fn validate(&self, tlm: &TlmSettings) -> Result<(), SettingsError> {
        let r = self.reach_m;
        let last_band = tlm.radial_bands_m[tlm.radial_bands_m.len() - 1];
        let checks: [RangeCheck; 5] = [
            (
                (0.0..=2.0).contains(&self.slicing_brightness),
                "draw_seeds.slicing_brightness",
                self.slicing_brightness.to_string(),
                "0 to 2",
            ),
            (
                r[0] >= 0.0
                    && r[1] > 0.0
                    && r.windows(2).all(|w| w[0] <= w[1])
                    && r.iter().all(|v| v.is_finite()),
                "draw_seeds.reach_m",
                format!("{r:?}"),
                "four increasing distances, metres (the first may be 0: no meshes)",
            ),
            (
                r[r.len() - 1] <= last_band,
                "draw_seeds.reach_m",
                format!("{r:?}"),
                "at most the last of tlm.radial_bands_m: seeds beyond it are never checked",
            ),
            (
                (0.0..=0.5).contains(&self.fade_fraction),
                "draw_seeds.fade_fraction",
                self.fade_fraction.to_string(),
                "0 to 0.5 of each LOD's reach",
            ),
            (
                self.samples == 1 || self.samples == SEED_SAMPLES,
                "draw_seeds.samples",
                self.samples.to_string(),
                "1 (alpha test) or 4 (multisampled, coverage from alpha)",
            ),
        ];
        first_out_of_range(checks)
    }
}
