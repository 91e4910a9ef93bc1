//! How it works: what every judge of one view shares (`ViewFrame`): the camera checked, where it
//! stands and how the renderer places the grid from there (on the Earth, or flat), the
//! projection's planes, the patterns checked against the settings; and the view over a region's
//! ground it opens (`View`).

use glam::{DMat4, DVec2, DVec3, DVec4};

use super::ground::{DemWindow, LandcoverTiles};
use super::vegetation::Vegetation;
use super::{Culls, OracleError, OracleInputs, View};
use crate::earth::placing::{EarthPlacing, ExactPlacing};
use crate::seeds::wind::Wind;

/// What every judge of one view shares: the camera checked and where it stands, the projection's
/// planes, the patterns checked against the settings.
pub(super) struct ViewFrame {
    pub(super) planes: [DVec4; 5],
    /// The eye, grid space, metres.
    pub(super) eye: DVec3,
    pub(super) extent_m: [f64; 2],
    /// Where the renderer draws the grid from this eye (on the Earth, or flat).
    pub(super) placing: ExactPlacing,
    /// How far a straight segment sags below the line between its ends' heights (`sag_per_m2`).
    pub(super) sag_per_m2: f64,
}

impl ViewFrame {
    pub(super) fn new(inputs: &OracleInputs) -> Result<Self, OracleError> {
        let &OracleInputs { dataset, settings, patterns, camera, viewport_px, .. } = inputs;
        camera.validate()?;
        let clip = camera.clip_from_view(viewport_px[0], viewport_px[1])? * camera.view_from_world();
        let spp = patterns.seeds_per_pattern;
        if patterns.count != settings.tlm.patterns
            || patterns.corner_colours != settings.tlm.corner_colours()
            || patterns.positions_unit.len() != patterns.count as usize * spp as usize
        {
            return Err(OracleError::Patterns {
                count: patterns.count,
                seeds_per_pattern: spp,
                positions: patterns.positions_unit.len(),
                wanted: settings.tlm.patterns,
            });
        }
        let manifest = &dataset.manifest;
        let spacing_m = manifest.height.spacing_m;
        let extent_m = dataset.height.pyramid.size.map(|n| f64::from(n.max(1) - 1) * spacing_m);
        let eye = camera.position_m - DVec3::new(manifest.origin_m[0], manifest.origin_m[1], 0.0);
        let curved = inputs.settings.render.curved_earth;
        let placing = EarthPlacing::new(manifest.earth.as_ref(), manifest.origin_m, curved).exact(eye);
        let sag_per_m2 = sag_per_m2(&placing);
        Ok(Self { planes: frustum_planes(clip), eye, extent_m, placing, sag_per_m2 })
    }

    /// The view over the ground of the rectangle [`region_min`, `region_max`] (grid metres).
    pub(super) fn view<'a>(
        self,
        inputs: &'a OracleInputs<'a>,
        culls: Culls,
        region_min: [f64; 2],
        region_max: [f64; 2],
    ) -> Result<View<'a>, OracleError> {
        let Self { planes, eye, extent_m, placing, sag_per_m2 } = self;
        let dataset = inputs.dataset;
        let dem = DemWindow::load(dataset, region_min, region_max)?;
        let landcover = LandcoverTiles::load(dataset, region_min, region_max)?;
        let vegetation = Vegetation::load(dataset, inputs.settings, region_min, region_max)?;
        let inside = |p: DVec2| p.x >= 0.0 && p.y >= 0.0 && p.x <= extent_m[0] && p.y <= extent_m[1];
        // An eye below the ground sees nothing (every seed reaching the occlusion test is hidden).
        let eye_underground = inside(eye.truncate()) && eye.z < dem.ground(eye.truncate()).0;
        let wind_reach_per_height = Wind::new(&inputs.settings.wind).reach_per_height();
        Ok(View {
            inputs,
            culls,
            dem,
            landcover,
            vegetation,
            planes,
            eye,
            eye_underground,
            extent_m,
            wind_reach_per_height,
            placing,
            sag_per_m2,
        })
    }
}

/// How far a straight segment dips below the line between its ends' heights, at the grid's
/// fraction t of the way: t (1 − t) (L² + 2 Δz²) times this, 1 / 2R, for a segment L long over the
/// grid rising Δz (L²: the Earth's fall under it; 2 Δz²: the verticals' convergence, which puts
/// its higher points over nearer grid points) (pass 3's `chord_sag_per_m2`, here from the exact mapping's second differences
/// a kilometre either way of the camera: the mean of x's and y's). 0 on the flat sheet.
pub(super) fn sag_per_m2(placing: &ExactPlacing) -> f64 {
    if !placing.is_round() {
        return 0.0;
    }
    let (eye, step_m) = (placing.camera_grid_m(), 1_000.0);
    let drop = |dx: f64, dy: f64| placing.position_rel_m(DVec3::new(eye.x + dx, eye.y + dy, 0.0)).z;
    let centre = drop(0.0, 0.0);
    let second = |dx: f64, dy: f64| drop(dx, dy) + drop(-dx, -dy) - 2.0 * centre;
    -(second(step_m, 0.0) + second(0.0, step_m)) / (4.0 * step_m * step_m)
}

/// The five planes (left, right, bottom, top, near; unit normals pointing inside) of a reversed-Z,
/// infinite-far clip matrix over camera-relative space (Gribb & Hartmann, as `Frustum`).
fn frustum_planes(clip_from_world: DMat4) -> [DVec4; 5] {
    let m = clip_from_world.transpose();
    let (x, y, z, w) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
    [w + x, w - x, w + y, w - y, w - z].map(|p| p / p.truncate().length().max(1e-300))
}
