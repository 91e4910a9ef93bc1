//! How it works: the light every pass shares besides the sun: the shadows of clouds drifting
//! over the land (Amara et al. 2007, § 5, `[clouds]`). The cloud layer is a field of fractal
//! value noise (`CLOUD_OCTAVES` octaves on a lattice that repeats every `CLOUD_PERIOD_CELLS` cells
//! of the largest, hashed like the seeds with its own salt) drifting downwind. A point's sunlight
//! is held back by the layer where the ray from it towards the sun crosses it, `above_top_m` over
//! the dataset's highest point; the cloud there is opaque where the noise passes a threshold
//! (with a soft edge, `CLOUD_EDGE`), the threshold being the noise's own quantile for the share of
//! the ground to shade, measured once on the field (`threshold_of_coverage`).
//!
//! The CPU does the f64 part per frame (`CloudShadowFrame::new`): where the camera's sun ray
//! meets the layer, in cells, modulo the period, so the shaders add only small camera-relative
//! offsets in f32. Each shader that lights something calls `sun_through_clouds`
//! (`shaders/shared/clouds.wgsl`) at its fragment's camera-relative position, so ground, seeds and
//! texcells are shaded alike at the same world point; `CloudShadowFrame::sun_visible` is its twin,
//! step for step in f32. On the Earth the layer is a shell over the datum, not a plane: a point d
//! from the camera lies d² / 2R lower in the camera's frame than over its own ground, and so does
//! the layer above it, so its height for the lookup is its camera-frame height plus that fall
//! (`CloudShadowFrame::on_earth`; 0 flat). No clouds (coverage or depth 0): the shaders return 1 before any
//! arithmetic, so frames are those of a build without clouds, bit for bit.

use std::sync::OnceLock;

use glam::DVec3;

use crate::config::{CloudSettings, RenderSettings};
use crate::gpu::layout::{CLOUD_EDGE, CLOUD_OCTAVES, CLOUD_PERIOD_CELLS, CLOUD_SALT};
use crate::seeds::{pcg, unit};

/// The lowest sun the shadows are cast from, as the sine of its elevation: a lower sun's shadows
/// would slide across the land faster than the clouds, and it lights almost nothing anyway.
const MIN_SUN_SIN: f64 = 0.087;

/// Points the noise's distribution is measured on (`threshold_of_coverage`).
const DISTRIBUTION_SAMPLES: u32 = 1 << 14;

/// What the shaders need of the clouds in one frame (`TerrainUniforms::cloud_field`,
/// `cloud_shift`, and pass 4's copies).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CloudShadowFrame {
    /// Where the camera's sun ray meets the cloud layer, in cells of the largest octave modulo the
    /// period (xy); cells per metre (z); the noise threshold of a cloud's edge (w).
    pub field: [f32; 4],
    /// Cells the meeting point moves per metre of height (xy); the share of sunlight a cloud's core
    /// holds back (z, 0: no clouds); the Earth's fall, 1 / 2R per square metre of horizontal
    /// distance from the camera (w, 0 flat).
    pub shift: [f32; 4],
}

impl CloudShadowFrame {
    /// The clouds of `settings` at the scene's time `time_s`, for a camera at `camera_grid_m` and
    /// a sun along `sun_dir` (unit, towards it), over a dataset whose highest point is `top_m`.
    pub fn new(
        settings: &CloudSettings,
        sun_dir: DVec3,
        top_m: f64,
        camera_grid_m: DVec3,
        time_s: f64,
    ) -> Self {
        if !settings.casting() {
            return Self::default();
        }
        let cells_per_m = 1.0 / settings.scale_m;
        let along_sun = sun_dir.truncate() / sun_dir.z.max(MIN_SUN_SIN);
        let (sin, cos) = settings.from_deg.to_radians().sin_cos();
        // Drifting from the compass direction (sin, cos), so towards its opposite.
        let drift_m = -glam::DVec2::new(sin, cos) * settings.speed_m_s * time_s;
        let layer_m = top_m + settings.above_top_m;
        let meet_m = camera_grid_m.truncate() + along_sun * (layer_m - camera_grid_m.z) - drift_m;
        let period = f64::from(CLOUD_PERIOD_CELLS);
        let cells = (meet_m * cells_per_m).map(|c| c.rem_euclid(period));
        let shift = -along_sun * cells_per_m;
        Self {
            field: [
                cells.x as f32,
                cells.y as f32,
                cells_per_m as f32,
                threshold_of_coverage(settings.coverage),
            ],
            shift: [shift.x as f32, shift.y as f32, settings.shadow_depth as f32, 0.0],
        }
    }

    /// These clouds over a ground that falls away from the camera by `fall_per_m2` d² at
    /// horizontal distance d (`earth::horizon::fall_per_m2`; 0 flat).
    pub fn on_earth(mut self, fall_per_m2: f64) -> Self {
        if self.shift[2] > 0.0 {
            self.shift[3] = fall_per_m2 as f32;
        }
        self
    }

    /// The share of the sun's light that reaches the point `rel_m` from the camera (metres,
    /// camera-relative world axes): the shaders' `sun_through_clouds`, step for step.
    pub fn sun_visible(&self, rel_m: [f32; 3]) -> f32 {
        let (threshold, depth) = (self.field[3], self.shift[2]);
        if depth <= 0.0 {
            return 1.0;
        }
        1.0 - depth * smoothstep(threshold - CLOUD_EDGE, threshold + CLOUD_EDGE, self.density_at(rel_m))
    }

    /// The noise density where the point `rel_m` from the camera looks at the sun, 0 to 1: how far
    /// inside a cloud (tests keep away from the edges with it).
    pub fn density_at(&self, rel_m: [f32; 3]) -> f32 {
        let [fx, fy, cells_per_m, _] = self.field;
        let [sx, sy, _, fall] = self.shift;
        let up_m = rel_m[2] + fall * (rel_m[0] * rel_m[0] + rel_m[1] * rel_m[1]);
        cloud_density([fx + rel_m[0] * cells_per_m + up_m * sx, fy + rel_m[1] * cells_per_m + up_m * sy])
    }
}

/// The unit vector towards the sun of `[render]` (x east, y north, z up).
pub fn sun_dir(render: &RenderSettings) -> DVec3 {
    let (azimuth, elevation) = (render.sun_azimuth_deg.to_radians(), render.sun_elevation_deg.to_radians());
    DVec3::new(azimuth.sin() * elevation.cos(), azimuth.cos() * elevation.cos(), elevation.sin())
}

/// The noise threshold that shades `coverage` of the ground: the field's own (1 − coverage)
/// quantile, measured once on `DISTRIBUTION_SAMPLES` hashed points. 0 shades nothing (above any
/// density, edge included), 1 everything.
pub fn threshold_of_coverage(coverage: f64) -> f32 {
    static SORTED: OnceLock<Vec<f32>> = OnceLock::new();
    if coverage <= 0.0 {
        return 1.0 + CLOUD_EDGE;
    }
    if coverage >= 1.0 {
        return -CLOUD_EDGE;
    }
    let sorted = SORTED.get_or_init(|| {
        let period = CLOUD_PERIOD_CELLS as f32;
        let mut densities: Vec<f32> = (0..DISTRIBUTION_SAMPLES)
            .map(|i| {
                let h = pcg(i ^ CLOUD_SALT);
                cloud_density([unit(h) * period, unit(pcg(h)) * period])
            })
            .collect();
        densities.sort_by(f32::total_cmp);
        densities
    });
    let rank = ((1.0 - coverage) * f64::from(DISTRIBUTION_SAMPLES)) as usize;
    sorted[rank.min(sorted.len() - 1)]
}

/// The clouds' density at `q` (cells of the largest octave), 0 to 1: the shaders' `cloud_density`.
pub fn cloud_density(q: [f32; 2]) -> f32 {
    let (mut sum, mut weight, mut total) = (0.0, 0.5, 0.0);
    let mut p = q;
    for octave in 0..CLOUD_OCTAVES {
        sum += weight * value_noise(p, octave);
        total += weight;
        p = [p[0] * 2.0, p[1] * 2.0];
        weight *= 0.5;
    }
    sum / total
}

/// Octave `octave`'s value noise at `q` (its own cells): the lattice's hashed values, blended
/// with a smooth step.
fn value_noise(q: [f32; 2], octave: u32) -> f32 {
    let cell = q.map(f32::floor);
    let f = [q[0] - cell[0], q[1] - cell[1]];
    let w = f.map(|t| t * t * (3.0 - 2.0 * t));
    let i = cell.map(|c| c as i32);
    let corner = |dx: i32, dy: i32| lattice(i[0] + dx, i[1] + dy, octave);
    let south = mix(corner(0, 0), corner(1, 0), w[0]);
    let north = mix(corner(0, 1), corner(1, 1), w[0]);
    mix(south, north, w[1])
}

/// The value of lattice point (x, y) of octave `octave`, 0 to 1, repeating every period.
fn lattice(x: i32, y: i32, octave: u32) -> f32 {
    let mask = (CLOUD_PERIOD_CELLS << octave) as i32 - 1;
    let (x, y) = ((x & mask) as u32, (y & mask) as u32);
    unit(pcg(x ^ pcg(y ^ pcg(octave ^ CLOUD_SALT))))
}

/// WGSL's `mix`.
fn mix(a: f32, b: f32, t: f32) -> f32 {
    a * (1.0 - t) + b * t
}

/// WGSL's `smoothstep`.
fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloudy(coverage: f64) -> CloudSettings {
        CloudSettings { coverage, ..crate::config::Settings::default().clouds }
    }

    /// The share of a 300 × 300 grid of points 250 m apart (some 50 × 50 of the largest clouds)
    /// that is in a cloud's shadow (past the edge's middle).
    fn shaded_share(frame: &CloudShadowFrame) -> f64 {
        let mut shaded = 0;
        for j in 0..300 {
            for i in 0..300 {
                let rel = [i as f32 * 250.0 - 37_500.0, j as f32 * 250.0 - 37_500.0, 0.0];
                shaded += u32::from(frame.density_at(rel) > frame.field[3]);
            }
        }
        f64::from(shaded) / 90_000.0
    }

    #[test]
    fn coverage_is_the_share_of_the_ground_in_shadow() {
        let sun = DVec3::new(0.3, 0.4, 0.866).normalize();
        for coverage in [0.1, 0.3, 0.5, 0.8] {
            // Far from where the distribution was measured, and a while later.
            let frame = CloudShadowFrame::new(
                &cloudy(coverage),
                sun,
                900.0,
                DVec3::new(4.1e5, -2.7e6, 1200.0),
                3600.0,
            );
            let share = shaded_share(&frame);
            println!("coverage {coverage}: {:.3} of the ground shaded", share);
            // Measured at most 0.007 off (docs/light.md): one square samples a few thousand
            // clouds; 0.04 still tells each coverage asked for from the next (0.2 apart).
            assert!((share - coverage).abs() < 0.04, "coverage {coverage} shades {share}");
        }
    }

    #[test]
    fn no_clouds_let_all_the_sun_through_and_an_overcast_sky_holds_back_its_depth_everywhere() {
        let sun = DVec3::new(0.0, 0.6, 0.8);
        let clear = CloudShadowFrame::new(&cloudy(0.0), sun, 0.0, DVec3::ZERO, 0.0);
        assert_eq!(clear, CloudShadowFrame::default());
        let overcast = CloudShadowFrame::new(
            &CloudSettings { shadow_depth: 0.7, ..cloudy(1.0) },
            sun,
            0.0,
            DVec3::ZERO,
            0.0,
        );
        for rel in [[0.0, 0.0, 0.0], [1234.5, -987.0, 55.0], [-9000.0, 3.0, -400.0]] {
            assert_eq!(clear.sun_visible(rel), 1.0);
            assert!((overcast.sun_visible(rel) - 0.3).abs() < 1e-6, "{}", overcast.sun_visible(rel));
        }
    }

    /// On the Earth a point lies d² / 2R lower in the camera's frame than over its own ground, as
    /// does the layer: the ground at the camera's level 10 km off sees the clouds the flat sheet's
    /// ground there sees, where without the fall it would look 7.8 m further towards the sun.
    #[test]
    fn on_the_earth_the_layer_falls_with_the_ground() {
        let sun = DVec3::new(0.3, 0.4, 0.5).normalize();
        let (camera, fall) = (DVec3::new(5000.0, 8000.0, 700.0), 1.0 / (2.0 * 6.371e6));
        let flat = CloudShadowFrame::new(&cloudy(0.5), sun, 500.0, camera, 10.0);
        let earth = flat.on_earth(fall);
        assert_eq!(
            CloudShadowFrame::new(&cloudy(0.0), sun, 500.0, camera, 10.0).on_earth(fall).shift[3],
            0.0
        );
        let (mut worst, mut unfallen) = (0.0f32, 0.0f32);
        for k in 0..200 {
            let angle = f64::from(k) * 0.1;
            let [x, y] = [(10_000.0 * angle.cos()) as f32, (10_000.0 * angle.sin()) as f32];
            let below = -(fall * f64::from(x * x + y * y)) as f32;
            let seen = earth.density_at([x, y, below]);
            worst = worst.max((seen - flat.density_at([x, y, 0.0])).abs());
            unfallen = unfallen.max((flat.density_at([x, y, below]) - flat.density_at([x, y, 0.0])).abs());
        }
        println!("10 km off: {worst} of the noise from the flat sheet's (without the fall: {unfallen})");
        assert!(worst < 1e-3 && unfallen > 10.0 * worst.max(1e-4), "{worst} {unfallen}");
    }

    #[test]
    fn shadows_drift_downwind_and_fall_along_the_sun() {
        let settings = CloudSettings { speed_m_s: 10.0, from_deg: 270.0, ..cloudy(0.5) };
        let sun = DVec3::new(0.6, 0.0, 0.8);
        let camera = DVec3::new(5000.0, 8000.0, 700.0);
        let now = CloudShadowFrame::new(&settings, sun, 500.0, camera, 100.0);
        let later = CloudShadowFrame::new(&settings, sun, 500.0, camera, 160.0);
        // A westerly carries the clouds 600 m east in a minute. A point 30 m higher has 30 m less
        // to climb towards the sun (in the east) to the layer, so it meets it 30 · 0.6 / 0.8 =
        // 22.5 m further west: it sees what the point 22.5 m west of the one below it sees.
        // Within 1e-3 of the noise (which spans 0 to 1; a cloud's soft edge is 0.04 wide): the same
        // point of the field reached two ways, in f32, rounds differently.
        for rel in [[0.0f32, 0.0, 0.0], [321.0, -77.0, 12.0], [-2500.0, 1800.0, -90.0]] {
            let downwind = [rel[0] + 600.0, rel[1], rel[2]];
            assert!((now.density_at(rel) - later.density_at(downwind)).abs() < 1e-3);
            let higher = [rel[0], rel[1], rel[2] + 30.0];
            let west = [rel[0] - 22.5, rel[1], rel[2]];
            assert!((now.density_at(higher) - now.density_at(west)).abs() < 1e-3);
        }
    }
}
