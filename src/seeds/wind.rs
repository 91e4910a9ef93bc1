//! How it works: the wind of the Virtual Forest (Wesslén & Seipel), one field for every
//! representation that draws a plant. A plant of height H bends around its base: a point of its
//! model at height fraction h (0 at the base, 1 at the top, clamped) moves horizontally by
//! `top · h²` and drops by `|top · h²|² / (2 |p|)` (`p` its offset from the base: the bend's arc,
//! to second order, so the plant does not stretch). The top's displacement, a fraction of H along
//! and across the wind, is
//! - a mean lean along the wind, growing with the square of the speed (`LEAN_PER_SPEED_SQ`, at
//!   most `MAX_LEAN`), which gusts weaken by up to `WIND_GUST_DEPTH` between their crests: a sine
//!   wave of `GUST_WAVELENGTH_M` travelling downwind at the wind's speed across the world;
//! - the plant's own sway, `WIND_SWAY_OF_LEAN` of the lean, at `WIND_SWAY_HZ_AT_1M / √H` (taller
//!   plants swing slower), with a smaller swing across the wind at another frequency (an ellipse),
//!   both phased by a hash of the seed's jitter, so neighbours never swing together.
//!
//! Before the bend, a leaf flutters: its vertices turn about the point it hangs from (its pivot,
//! `MeshVertex::pivot_model_m`: the tree generator writes it, other models' vertices are their own
//! pivots) about the horizontal axis across the wind, by up to `WIND_FLUTTER_RAD_PER_LEAN` × the
//! lean (at most `WIND_FLUTTER_MAX_RAD`) at a frequency and phase hashed from the pivot; the move is
//! capped at `WIND_FLUTTER_MAX_PER_HEIGHT` of the plant's height. Billboard clouds bend and do not
//! flutter (their leaves are texels), which at the distances they are drawn is under a pixel.
//!
//! The shaders evaluate it per vertex (`shaders/shared/wind.wgsl`) from the seed's record alone, so
//! a seed's mesh and its billboard clouds bend the same way and a cross-fade shows one plant. Rocks
//! do not bend (`bend_of`). The field is bounded: no point moves farther than
//! `reach_per_height` × H, which pass 3, its twin and the exact oracle add to each seed's bounds.
//! Time is the caller's (`WindSettings::time_of_frame_s`), so a frame number always shows the
//! same sway; with no wind every offset is exactly zero and the shaders skip the field.

use std::f64::consts::TAU;

use glam::Vec3;

use crate::classes::SpeciesKind;
use crate::config::WindSettings;
use crate::gpu::layout::{
    WIND_CROSS_HZ_RATIO, WIND_CROSS_OF_SWAY, WIND_FLUTTER_HZ, WIND_FLUTTER_MAX_PER_HEIGHT,
    WIND_FLUTTER_MAX_RAD, WIND_FLUTTER_RAD_PER_LEAN, WIND_GUST_DEPTH, WIND_SWAY_HZ_AT_1M, WIND_SWAY_OF_LEAN,
};

use super::pcg;

/// Mean lean of a plant's top, as a fraction of its height, per (metre per second)² of wind: 4 %
/// at 10 m/s.
pub const LEAN_PER_SPEED_SQ: f64 = 4.0e-4;
/// The most a plant's top leans on average, as a fraction of its height (a storm).
pub const MAX_LEAN: f64 = 0.12;
/// Wavelength of the gusts travelling downwind, metres.
pub const GUST_WAVELENGTH_M: f64 = 80.0;

/// How much the wind bends a kind of seed: plants fully, rocks not at all.
pub fn bend_of(kind: SpeciesKind) -> f32 {
    match kind {
        SpeciesKind::Tree | SpeciesKind::Bush => 1.0,
        SpeciesKind::Rock => 0.0,
    }
}

/// The wind of a set of settings: its direction and how far it bends plants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wind {
    /// Unit vector the wind blows towards, world (x east, y north).
    pub downwind: [f64; 2],
    /// Speed, metres per second.
    pub speed_m_s: f64,
    /// Mean lean of a top at the gusts' crests, fraction of the plant's height.
    pub lean_per_height: f64,
    /// Amplitude of a top's own sway along the wind, fraction of the plant's height.
    pub sway_per_height: f64,
}

/// What the draw shaders need of the wind in one frame (`DrawSeedsUniforms::wind`, `wind_wave`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WindFrame {
    /// Downwind unit vector (xy), lean and sway per height (zw).
    pub wind: [f32; 4],
    /// Wind time in seconds (x), the gusts' wavenumber per metre (y), their phase at the camera
    /// (z, radians in [0, 2π)), unused (w).
    pub wave: [f32; 4],
}

impl Wind {
    /// The wind of `settings`.
    pub fn new(settings: &WindSettings) -> Self {
        let (sin, cos) = settings.from_deg.to_radians().sin_cos();
        // Blowing from the compass direction (sin, cos), so towards its opposite.
        let downwind = [-sin, -cos];
        let speed_m_s = settings.speed_m_s;
        let lean_per_height = (LEAN_PER_SPEED_SQ * speed_m_s * speed_m_s).min(MAX_LEAN);
        Self {
            downwind,
            speed_m_s,
            lean_per_height,
            sway_per_height: f64::from(WIND_SWAY_OF_LEAN) * lean_per_height,
        }
    }

    /// Whether anything moves.
    pub fn blowing(&self) -> bool {
        self.lean_per_height > 0.0
    }

    /// The farthest any point of a plant moves, as a fraction of its height: a leaf's flutter (at
    /// most its cap), then the bend: the top's largest displacement d (lean and sway along, sway
    /// across) plus the bend's drop, at most d² / 2. 0 in still air.
    pub fn reach_per_height(&self) -> f64 {
        if !self.blowing() {
            return 0.0;
        }
        let along = self.lean_per_height + self.sway_per_height;
        let across = f64::from(WIND_CROSS_OF_SWAY) * self.sway_per_height;
        let top = along.hypot(across);
        f64::from(WIND_FLUTTER_MAX_PER_HEIGHT) + top + 0.5 * top * top
    }

    /// The shaders' constants at wind time `time_s` for a camera at `camera_xy_m` (dataset CRS):
    /// the gusts' phase is taken at the camera in f64, so that camera-relative positions in f32
    /// place them on the world, not on the view.
    pub fn frame(&self, time_s: f64, camera_xy_m: [f64; 2]) -> WindFrame {
        let wavenumber_per_m = TAU / GUST_WAVELENGTH_M;
        let camera_along_m = camera_xy_m[0] * self.downwind[0] + camera_xy_m[1] * self.downwind[1];
        let phase = (wavenumber_per_m * (camera_along_m - self.speed_m_s * time_s)).rem_euclid(TAU);
        let [x, y] = self.downwind;
        WindFrame {
            wind: [x as f32, y as f32, self.lean_per_height as f32, self.sway_per_height as f32],
            wave: [time_s as f32, wavenumber_per_m as f32, phase as f32, 0.0],
        }
    }
}

impl WindFrame {
    /// Where the top of a seed `height_m` tall anchored at `anchor_rel_m` (camera-relative) has
    /// moved, metres: the shaders' `wind_top_m`, step for step in f32.
    pub fn top_m(&self, anchor_rel_m: [f32; 3], height_m: f32, jitter: u32) -> [f32; 2] {
        let tau = std::f32::consts::TAU;
        let [x, y, lean_per_height, sway_per_height] = self.wind;
        let [time_s, wavenumber_per_m, phase, _] = self.wave;
        let gust = 0.5 + 0.5 * ((anchor_rel_m[0] * x + anchor_rel_m[1] * y) * wavenumber_per_m + phase).sin();
        let lean = lean_per_height * (1.0 - WIND_GUST_DEPTH * (1.0 - gust));
        let hz = WIND_SWAY_HZ_AT_1M / height_m.max(1.0).sqrt();
        let phases = pcg(jitter);
        let turn_along = (hz * time_s + (phases & 0xffff) as f32 / 65536.0).fract();
        let turn_across = (hz * WIND_CROSS_HZ_RATIO * time_s + (phases >> 16) as f32 / 65536.0).fract();
        let along = lean + sway_per_height * (tau * turn_along).sin();
        let across = WIND_CROSS_OF_SWAY * sway_per_height * (tau * turn_across).sin();
        [(x * along - y * across) * height_m, (y * along + x * across) * height_m]
    }

    /// A leaf's vertex `leaf_m` from its pivot (world axes, metres) turned about the pivot: the
    /// shaders' `wind_flutter`.
    pub fn flutter(&self, leaf_m: [f32; 3], pivot_model_m: [f32; 3], height_m: f32) -> [f32; 3] {
        let tau = std::f32::consts::TAU;
        let [x, y, lean_per_height, _] = self.wind;
        let p = pivot_model_m.map(f32::to_bits);
        let key = pcg(p[0] ^ pcg(p[1] ^ pcg(p[2])));
        let hz = WIND_FLUTTER_HZ * (1.0 + 0.5 * (key >> 16) as f32 / 65536.0);
        let turn = (hz * self.wave[0] + (key & 0xffff) as f32 / 65536.0).fract();
        let angle =
            (WIND_FLUTTER_RAD_PER_LEAN * lean_per_height).min(WIND_FLUTTER_MAX_RAD) * (tau * turn).sin();
        let k = Vec3::new(-y, x, 0.0);
        let v = Vec3::from(leaf_m);
        let turned = v * angle.cos() + k.cross(v) * angle.sin() + k * (k.dot(v) * (1.0 - angle.cos()));
        let moved = turned - v;
        let cap_m = WIND_FLUTTER_MAX_PER_HEIGHT * height_m;
        let moved_m = moved.length();
        if moved_m > cap_m { (v + moved * (cap_m / moved_m)).to_array() } else { turned.to_array() }
    }
}

/// A point `offset_m` from the base of a seed `height_m` tall (world axes, metres) bent so that
/// its top moves by `top_m`: the shaders' `wind_bend`.
pub fn bend(offset_m: [f32; 3], top_m: [f32; 2], height_m: f32) -> [f32; 3] {
    let h = (offset_m[2] / height_m).clamp(0.0, 1.0);
    let moved = [top_m[0] * (h * h), top_m[1] * (h * h)];
    let length = offset_m.iter().map(|v| v * v).sum::<f32>().sqrt();
    let drop = (moved[0] * moved[0] + moved[1] * moved[1]) / (2.0 * length.max(1e-3));
    [offset_m[0] + moved[0], offset_m[1] + moved[1], offset_m[2] - drop]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wind(speed_m_s: f64, from_deg: f64) -> Wind {
        Wind::new(&WindSettings { speed_m_s, from_deg, frame_rate_hz: 30.0 })
    }

    #[test]
    fn a_westerly_blows_east_and_still_air_moves_nothing() {
        let west = wind(10.0, 270.0);
        assert!((west.downwind[0] - 1.0).abs() < 1e-12 && west.downwind[1].abs() < 1e-12);
        assert!((west.lean_per_height - 0.04).abs() < 1e-12);
        let still = wind(0.0, 123.0);
        assert!(!still.blowing());
        assert_eq!(still.reach_per_height(), 0.0);
        assert_eq!(still.frame(5.0, [1e6, 2e6]).wind[2..], [0.0, 0.0]);
    }

    #[test]
    fn the_lean_saturates_and_the_reach_bounds_lean_and_sway() {
        assert_eq!(wind(40.0, 0.0).lean_per_height, MAX_LEAN);
        let w = wind(10.0, 0.0);
        assert!(w.reach_per_height() > w.lean_per_height + w.sway_per_height);
        assert!(w.reach_per_height() < 2.0 * (w.lean_per_height + w.sway_per_height));
    }

    #[test]
    fn no_point_of_a_plant_moves_farther_than_the_reach() {
        // Every wind, time, seed, height and point of the model (tips far out from the trunk,
        // points above the top): the bend stays within reach_per_height × height.
        let mut worst = 0.0f64;
        for (k, speed_m_s) in [2.0, 10.0, 25.0, 40.0].into_iter().enumerate() {
            let w = wind(speed_m_s, 37.0 * k as f64);
            let bound = w.reach_per_height();
            for step in 0..400u32 {
                let h = pcg(step.wrapping_mul(7919) + k as u32);
                let frame = w.frame(f64::from(h % 10_000) * 0.0137, [f64::from(h % 977) * 40.0, 3.9e6]);
                let height_m = 0.5 + (h % 400) as f32 / 10.0;
                let anchor = [(h % 300) as f32 - 150.0, (h % 170) as f32 - 85.0, -20.0];
                let top = frame.top_m(anchor, height_m, pcg(h));
                for (fx, fz) in [(0.0, 1.0), (0.5, 0.2), (0.9, 0.05), (0.01, 1.3), (0.3, 0.7), (0.0, 0.0)] {
                    let p = [fx * height_m, -0.5 * fx * height_m, fz * height_m];
                    // A leaf hanging from a point a little below and inside it (as large as the
                    // plant, to reach the flutter's cap).
                    let leaf_m = [0.1 * p[0], 0.3 * height_m * fx, 0.2 * height_m];
                    let pivot = [p[0] - leaf_m[0], p[1] - leaf_m[1], p[2] - leaf_m[2]];
                    let f = frame.flutter(leaf_m, pivot, height_m);
                    let q = bend([pivot[0] + f[0], pivot[1] + f[1], pivot[2] + f[2]], top, height_m);
                    let moved =
                        ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt();
                    let ratio = f64::from(moved / height_m) / bound;
                    worst = worst.max(ratio);
                    assert!(ratio <= 1.0 + 1e-4, "{speed_m_s} m/s, {p:?} → {q:?}: {ratio}");
                }
            }
        }
        // And the bound is not loose by much: some point comes near it.
        assert!(worst > 0.8, "the reach is loose: the farthest point moved {worst} of it");
    }

    #[test]
    fn gusts_travel_downwind_at_the_wind_speed() {
        // Riding downwind with the gusts, the phase at the camera stays put.
        let w = wind(8.0, 270.0);
        let a = w.frame(0.0, [500_000.0, 4e6]);
        let b = w.frame(2.5, [500_000.0 + 8.0 * 2.5, 4e6]);
        let turn = (a.wave[2] - b.wave[2]).abs();
        assert!(turn < 1e-4 || (turn - TAU as f32).abs() < 1e-4, "{a:?} {b:?}");
        assert!((0.0..TAU as f32).contains(&a.wave[2]));
    }
}
