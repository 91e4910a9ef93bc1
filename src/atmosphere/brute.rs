//! How it works: the atmosphere's truth, by brute force, for judging the look-up tables the GPU
//! draws the sky with. It shares no table with them: every transmittance is a fresh quadrature
//! along its own ray, and every order of scattering beyond the first is followed by Monte Carlo.
//!
//! The radiance reaching a point along a view ray is the light the air scatters towards it along
//! that ray up to the ground or the top (the ground's own radiance is the ground pass's, not the
//! sky's). It is split in two:
//! - **single scattering** (sun → air → eye), a midpoint quadrature along the view ray whose every
//!   node marches its own ray to the sun (0 where the Earth hides it);
//! - **every higher order** (sun → air or ground → … → air → eye), an estimate over random paths
//!   per channel: each segment of a path is forced to hold a stop (free flight conditioned on
//!   one, the path weighted by its chance), where the sun's light is taken by next-event
//!   estimation (none at the view ray's own stop: that is single scattering), and where the
//!   segment ends on the ground the ground's light as well, weighted by the chance of passing;
//!   the path goes on from the stop or the ground, drawn by those chances, in a direction drawn
//!   exactly from the phase functions (Rayleigh and Cornette–Shanks by rejection) or the
//!   ground's cosine lobe. It is unbiased for the same discretised medium (the extinction held at
//!   each step's midpoint), and reports its standard error.
//!
//! Steps grow with altitude (`STEP_FRACTION` of the altitude plus the aerosols' scale height, so
//! a twentieth of a scale height near the ground), fine enough that halving them moves a sky
//! radiance by less than 0.1 % (the test below).

use glam::DVec3;

use super::{Atmosphere, Exit, Medium, Rgb, mie_phase, rayleigh_phase};

/// A step along any ray, as a fraction of (its start's altitude + the aerosols' scale height).
pub const STEP_FRACTION: f64 = 0.05;

/// The longest step, km: the air above 60 km holds too little to matter, but a ray through it
/// still needs to find the ground it may meet.
const MAX_STEP_KM: f64 = 4.0;

/// Orders of scattering a path follows at most (at 0.3 of vertical optical depth in the blue the
/// 10th order carries under 10⁻⁴ of the light).
const MAX_ORDER: u32 = 64;

/// The sky at one view direction: its two parts and how sure the random one is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkySample {
    /// Sun → air → eye, by quadrature.
    pub single: Rgb,
    /// Every higher order, the mean over the paths.
    pub multiple: Rgb,
    /// The standard error of `multiple`'s mean.
    pub multiple_std_error: Rgb,
}

impl SkySample {
    /// The whole radiance, per unit of the sun's irradiance.
    pub fn radiance(&self) -> Rgb {
        std::array::from_fn(|c| self.single[c] + self.multiple[c])
    }
}

/// The brute-force integrator over one atmosphere.
#[derive(Debug, Clone, Copy)]
pub struct Brute {
    /// The model it integrates.
    pub air: Atmosphere,
    /// Its step, as `STEP_FRACTION` is (halved to check convergence).
    pub step_fraction: f64,
}

impl Brute {
    /// The integrator at its standard step.
    pub fn new(air: Atmosphere) -> Self {
        Self { air, step_fraction: STEP_FRACTION }
    }

    fn step_km(&self, altitude_km: f64) -> f64 {
        (self.step_fraction * (altitude_km.max(0.0) + self.air.mie_scale_height_km)).min(MAX_STEP_KM)
    }

    /// Walks the ray from `origin_km` along `dir` for `length_km`, one midpoint medium per step.
    fn march(
        &self,
        origin_km: DVec3,
        dir: DVec3,
        length_km: f64,
        mut visit: impl FnMut(f64, f64, &Medium) -> bool,
    ) {
        let mut t = 0.0;
        while t < length_km {
            let dt = self.step_km(self.air.altitude_km(origin_km + dir * t)).min(length_km - t);
            let mid = t + 0.5 * dt;
            let medium = self.air.medium(self.air.altitude_km(origin_km + dir * mid));
            if !visit(mid, dt, &medium) {
                return;
            }
            t += dt;
        }
    }

    /// The share of the sun's light that reaches `p_km` along `sun` (unit, towards it): 0 where
    /// the Earth is in the way.
    pub fn sun_transmittance(&self, p_km: DVec3, sun: DVec3) -> Rgb {
        match self.air.exit(p_km, sun) {
            Some(Exit::Top(length)) => {
                let mut depth = [0.0; 3];
                self.march(p_km, sun, length, |_, dt, m| {
                    (0..3).for_each(|c| depth[c] += m.extinction[c] * dt);
                    true
                });
                depth.map(|d| (-d).exp())
            }
            Some(Exit::Ground(_)) => [0.0; 3],
            // Above the air looking away from it: nothing in the way.
            None => [1.0; 3],
        }
    }

    /// Single scattering towards `origin_km` from along `dir` (unit), the sun along `sun`.
    pub fn single_scattering(&self, origin_km: DVec3, dir: DVec3, sun: DVec3) -> Rgb {
        let Some((start, end, _)) = self.air.segment(origin_km, dir) else { return [0.0; 3] };
        let nu = dir.dot(sun);
        let (rayleigh, mie) = (rayleigh_phase(nu), mie_phase(nu, self.air.mie_g));
        let from = origin_km + dir * start;
        let (mut depth, mut radiance) = ([0.0; 3], [0.0; 3]);
        self.march(from, dir, end - start, |mid, dt, m| {
            let sunlight = self.sun_transmittance(from + dir * mid, sun);
            for c in 0..3 {
                let seen = (-(depth[c] + 0.5 * m.extinction[c] * dt)).exp();
                let scattered = m.rayleigh_scattering[c] * rayleigh + m.mie_scattering * mie;
                radiance[c] += seen * scattered * sunlight[c] * dt;
                depth[c] += m.extinction[c] * dt;
            }
            true
        });
        radiance
    }

    /// Every order of scattering above the first towards `origin_km` from along `dir`, over
    /// `paths` paths per channel drawn from `seed`: the mean and its standard error.
    pub fn multiple_scattering(
        &self,
        origin_km: DVec3,
        dir: DVec3,
        sun: DVec3,
        paths: u32,
        seed: u64,
    ) -> (Rgb, Rgb) {
        let mut mean = [0.0; 3];
        let mut error = [0.0; 3];
        for c in 0..3 {
            let mut rng = Rng(seed ^ (c as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
            let (mut sum, mut sum_sq) = (0.0, 0.0);
            for _ in 0..paths {
                let value = self.path(origin_km, dir, sun, c, &mut rng);
                sum += value;
                sum_sq += value * value;
            }
            let n = paths as f64;
            mean[c] = sum / n;
            error[c] = ((sum_sq / n - mean[c] * mean[c]).max(0.0) / (n - 1.0).max(1.0)).sqrt();
        }
        (mean, error)
    }

    /// Both parts of the sky along `dir` from `origin_km`.
    pub fn sky(&self, origin_km: DVec3, dir: DVec3, sun: DVec3, paths: u32, seed: u64) -> SkySample {
        let (multiple, multiple_std_error) = self.multiple_scattering(origin_km, dir, sun, paths, seed);
        SkySample { single: self.single_scattering(origin_km, dir, sun), multiple, multiple_std_error }
    }

    /// One path's light of the second order and above, channel `c`. Every segment is forced to
    /// hold a stop (weighted by the chance of one), where the sun's light is taken, and where it
    /// ends on the ground, the ground's as well, weighted by the chance of passing; the path goes
    /// on from one of the two, drawn by those chances.
    fn path(&self, origin_km: DVec3, dir: DVec3, sun: DVec3, c: usize, rng: &mut Rng) -> f64 {
        let Some((start, end, _)) = self.air.segment(origin_km, dir) else { return 0.0 };
        let from = origin_km + dir * start;
        // Past the segment the view ray meets the ground or space: not the air's light.
        let walk = self.walk(from, dir, end - start, c);
        let Some((t, medium)) = walk.forced_stop(rng) else { return 0.0 };
        let mut p = from + dir * t;
        let mut weight = walk.stopped() * medium.scattering(c) / medium.extinction[c];
        let mut d = self.scatter(dir, &medium, c, rng);
        let mut value = 0.0;
        for _ in 1..MAX_ORDER {
            let Some(exit) = self.air.exit(p, d) else { break };
            let (length, ground) = match exit {
                Exit::Ground(t) => (t, true),
                Exit::Top(t) => (t, false),
            };
            let walk = self.walk(p, d, length, c);
            let stopped = walk.stopped();
            let Some((t, m)) = walk.forced_stop(rng) else { break };
            let stop = p + d * t;
            let nu = d.dot(sun);
            let phase = m.rayleigh_scattering[c] * rayleigh_phase(nu)
                + m.mie_scattering * mie_phase(nu, self.air.mie_g);
            value += weight * stopped * phase / m.extinction[c] * self.sun_transmittance(stop, sun)[c];
            let albedo = self.air.ground_albedo[c];
            let on_ground = p + d * length;
            if ground {
                let lit = on_ground.normalize().dot(sun).max(0.0);
                if lit > 0.0 {
                    let sunlight = self.sun_transmittance(on_ground, sun)[c];
                    value += weight * (1.0 - stopped) * albedo / std::f64::consts::PI * lit * sunlight;
                }
            }
            if ground && rng.unit() >= stopped {
                weight *= albedo;
                let normal = on_ground.normalize();
                // Just above the ground, so the next ray does not meet it again at once.
                p = normal * (self.air.bottom_radius_km + 1e-9);
                d = rng.cosine_around(normal);
            } else {
                // Towards space the stop was forced: its chance weighs the path.
                weight *= if ground { 1.0 } else { stopped } * m.scattering(c) / m.extinction[c];
                p = stop;
                d = self.scatter(d, &m, c, rng);
            }
            if weight < 1e-3 {
                // Russian roulette: unbiased, and a path's last orders cost nothing.
                if rng.unit() > weight / 1e-3 {
                    break;
                }
                weight = 1e-3;
            }
        }
        value
    }

    /// The ray from `origin_km` along `dir` for `length_km`, step by step, in channel `c`.
    fn walk(&self, origin_km: DVec3, dir: DVec3, length_km: f64, c: usize) -> Walk {
        let mut steps = Vec::new();
        let mut depth = 0.0;
        self.march(origin_km, dir, length_km, |mid, dt, m| {
            steps.push((mid - 0.5 * dt, dt, *m));
            depth += m.extinction[c] * dt;
            true
        });
        Walk { steps, depth, c }
    }

    /// A new direction after scattering at a point of medium `m`, travelling along `d`: Rayleigh
    /// or Mie by their shares of the scattering, each phase drawn exactly.
    fn scatter(&self, d: DVec3, m: &Medium, c: usize, rng: &mut Rng) -> DVec3 {
        let rayleigh = rng.unit() * m.scattering(c) < m.rayleigh_scattering[c];
        let cos_theta = loop {
            let mu =
                if rayleigh { 2.0 * rng.unit() - 1.0 } else { henyey_greenstein(self.air.mie_g, rng.unit()) };
            // Both phases are (1 + μ²) / 2 times what μ was drawn from (uniform, Henyey–Greenstein).
            if rng.unit() * 2.0 <= 1.0 + mu * mu {
                break mu;
            }
        };
        around(d, cos_theta, 2.0 * std::f64::consts::PI * rng.unit())
    }
}

/// A ray's steps (start, length, medium) and its optical depth, in one channel.
struct Walk {
    steps: Vec<(f64, f64, Medium)>,
    depth: f64,
    c: usize,
}

impl Walk {
    /// The chance a photon is stopped along the whole ray.
    fn stopped(&self) -> f64 {
        1.0 - (-self.depth).exp()
    }

    /// Where a photon stops, given that it does (free flight conditioned on the ray), with the
    /// medium there.
    fn forced_stop(&self, rng: &mut Rng) -> Option<(f64, Medium)> {
        let target = -(1.0 - rng.unit() * self.stopped()).ln();
        let mut depth = 0.0;
        for &(start, dt, m) in &self.steps {
            let step_depth = m.extinction[self.c] * dt;
            if depth + step_depth >= target {
                return Some((start + (target - depth) / m.extinction[self.c], m));
            }
            depth += step_depth;
        }
        // Rounding left the target a hair past the end: the last step's end.
        self.steps.last().map(|&(start, dt, m)| (start + dt, m))
    }
}

/// A cosine drawn from Henyey and Greenstein's phase with asymmetry `g`, by inversion.
fn henyey_greenstein(g: f64, u: f64) -> f64 {
    if g.abs() < 1e-6 {
        return 2.0 * u - 1.0;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// The unit direction at angle acos(`cos_theta`) from `axis`, turned by `phi` around it.
fn around(axis: DVec3, cos_theta: f64, phi: f64) -> DVec3 {
    let (x, y) = axis.any_orthonormal_pair();
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    (axis * cos_theta + (x * phi.cos() + y * phi.sin()) * sin_theta).normalize()
}

/// SplitMix64: small, fast, and the same sequence everywhere for a seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A direction around `normal` with density cos θ / π.
    fn cosine_around(&mut self, normal: DVec3) -> DVec3 {
        let u = self.unit();
        around(normal, (1.0 - u).sqrt(), 2.0 * std::f64::consts::PI * self.unit())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn up_at(altitude_km: f64) -> DVec3 {
        DVec3::new(0.0, 0.0, Atmosphere::earth().bottom_radius_km + altitude_km)
    }

    fn direction(zenith_deg: f64, azimuth_deg: f64) -> DVec3 {
        let (z, a) = (zenith_deg.to_radians(), azimuth_deg.to_radians());
        DVec3::new(z.sin() * a.cos(), z.sin() * a.sin(), z.cos())
    }

    #[test]
    fn the_zenith_transmittance_is_the_closed_form_depth() {
        // Straight up from the ground the optical depth has a closed form: the scale heights
        // times the densities' fall over 100 km, plus the ozone tent's area.
        let air = Atmosphere::earth();
        let brute = Brute::new(air);
        let t = brute.sun_transmittance(up_at(0.0), DVec3::Z);
        for (c, t) in t.into_iter().enumerate() {
            let rayleigh = air.rayleigh_scattering_per_km[c] * 8.0 * (1.0 - (-100.0f64 / 8.0).exp());
            let mie = air.mie_extinction_per_km * 1.2 * (1.0 - (-100.0f64 / 1.2).exp());
            let ozone = air.ozone_absorption_per_km[c] * 15.0;
            let expected = (-(rayleigh + mie + ozone)).exp();
            assert!((t / expected - 1.0).abs() < 2e-4, "channel {c}: {t} against {expected}");
        }
        assert_eq!(brute.sun_transmittance(up_at(0.0), -DVec3::Z), [0.0; 3]);
    }

    #[test]
    fn halving_the_steps_moves_the_single_scattering_by_under_a_thousandth() {
        let coarse = Brute::new(Atmosphere::earth());
        let fine = Brute { step_fraction: STEP_FRACTION / 2.0, ..coarse };
        let sun = direction(80.0, 0.0);
        for (altitude, zenith) in [(0.0, 0.0), (0.0, 89.0), (1.0, 91.0), (10.0, 60.0), (10.0, 95.0)] {
            let dir = direction(zenith, 30.0);
            let (a, b) = (
                coarse.single_scattering(up_at(altitude), dir, sun),
                fine.single_scattering(up_at(altitude), dir, sun),
            );
            for c in 0..3 {
                assert!(
                    b[c] > 0.0 && (a[c] / b[c] - 1.0).abs() < 1e-3,
                    "{altitude} km, {zenith}°: {a:?} against {b:?}"
                );
            }
        }
    }

    #[test]
    fn multiple_scattering_is_a_fifth_to_a_half_of_a_day_sky_and_its_error_is_stated() {
        // Hillaire (2020, fig. 8) and Bruneton (2008): at noon the higher orders add a few tens of
        // percent to the zenith's blue, more towards the horizon.
        let brute = Brute::new(Atmosphere::earth());
        let sky = brute.sky(up_at(0.0), DVec3::Z, direction(30.0, 0.0), 4096, 7);
        for c in 0..3 {
            let share = sky.multiple[c] / sky.radiance()[c];
            assert!((0.05..0.6).contains(&share), "channel {c}: higher orders {share} of the sky");
            assert!(sky.multiple_std_error[c] < 0.05 * sky.multiple[c], "{sky:?}");
        }
        assert!(
            sky.radiance()[2] > sky.radiance()[1] && sky.radiance()[1] > sky.radiance()[0],
            "blue sky: {sky:?}"
        );
    }
}
