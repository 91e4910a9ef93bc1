//! How it works: the air between the camera, the ground and the sun, as one scattering model
//! (Hillaire 2020, "A Scalable and Production Ready Sky and Atmosphere Rendering Technique", and
//! Bruneton & Neyret 2008, whose Earth parameters it shares). The atmosphere is a spherical shell
//! from `bottom_radius_km` to `top_radius_km` around the Earth's centre, holding three media whose
//! densities depend on altitude alone: Rayleigh scattering by the molecules (exponential, scale
//! height `rayleigh_scale_height_km`), Mie scattering and absorption by aerosols (exponential,
//! `mie_scale_height_km`, Cornette–Shanks phase with asymmetry `mie_g`) and absorption by ozone (a
//! tent of half width `ozone_half_width_km` around `ozone_centre_km`). Light reflected by the
//! ground (Lambertian, `ground_albedo`) feeds the multiple scattering. Radiances are per unit of
//! the sun's irradiance on a plane facing it at the top of the atmosphere, per RGB channel.
//!
//! This module is the model in f64 (`Atmosphere`, its media and phase functions, the shell's ray
//! geometry) and its truth, `brute`: single scattering by dense quadrature and every higher order
//! by Monte Carlo paths, sharing no table with what it judges. The GPU evaluates the same model
//! through look-up tables (`passes::atmosphere`, twin `reference::atmosphere`). Lengths are
//! kilometres throughout: the shaders work in f32 around the Earth's centre, where a kilometre
//! keeps 0.5 m of precision at the surface.

pub mod brute;

use glam::DVec3;
use serde::Deserialize;

/// Linear RGB, one value per channel.
pub type Rgb = [f64; 3];

/// The luminance (CIE Y) of linear sRGB's red, green and blue primaries, white 1 (IEC 61966-2-1,
/// D65): the Y row of its matrix to CIE XYZ.
pub const LUMINANCE_OF_LINEAR_SRGB: Rgb = [0.2126729, 0.7151522, 0.0721750];

/// The atmosphere's physical parameters: the `[atmosphere]` table's model part. The defaults
/// (`Atmosphere::earth`) are Bruneton's and Hillaire's clear-sky Earth.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Atmosphere {
    /// Radius of the ground the air rests on, km (the sphere the model's Earth is).
    pub bottom_radius_km: f64,
    /// Radius above which there is no air, km.
    pub top_radius_km: f64,
    /// Rayleigh scattering coefficient at the ground, per km, RGB.
    pub rayleigh_scattering_per_km: Rgb,
    /// Altitude over which the molecules' density falls by e, km.
    pub rayleigh_scale_height_km: f64,
    /// Mie scattering coefficient at the ground, per km (grey).
    pub mie_scattering_per_km: f64,
    /// Mie extinction (scattering + absorption) at the ground, per km (grey).
    pub mie_extinction_per_km: f64,
    /// Altitude over which the aerosols' density falls by e, km.
    pub mie_scale_height_km: f64,
    /// The aerosols' phase asymmetry (Cornette–Shanks), 0 to < 1: forward scattering.
    pub mie_g: f64,
    /// Ozone absorption at the layer's peak density, per km, RGB.
    pub ozone_absorption_per_km: Rgb,
    /// Altitude of the ozone layer's peak, km.
    pub ozone_centre_km: f64,
    /// Half width of the ozone layer's tent, km: its density falls linearly to 0 this far from
    /// the peak.
    pub ozone_half_width_km: f64,
    /// The ground's Lambertian albedo under the air, RGB (feeds the multiple scattering).
    pub ground_albedo: Rgb,
    /// The sun's angular radius, radians (its disk).
    pub sun_angular_radius_rad: f64,
}

/// What the air scatters and removes at one altitude, per km.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    /// Rayleigh scattering, RGB.
    pub rayleigh_scattering: Rgb,
    /// Mie scattering (grey).
    pub mie_scattering: f64,
    /// Everything that leaves the ray: scattering and absorption of the three media, RGB.
    pub extinction: Rgb,
}

impl Medium {
    /// Scattering of both kinds in channel `c`.
    pub fn scattering(&self, c: usize) -> f64 {
        self.rayleigh_scattering[c] + self.mie_scattering
    }
}

impl Atmosphere {
    /// The clear-sky Earth of Bruneton's demo and Hillaire's paper: Rayleigh (5.802, 13.558, 33.1)
    /// × 10⁻³ per km with an 8 km scale height, Mie 3.996 × 10⁻³ scattering and 4.40 × 10⁻³
    /// extinction with 1.2 km and g = 0.8, ozone (0.650, 1.881, 0.085) × 10⁻³ around 25 km, a
    /// 6,360 km Earth under 100 km of air, ground albedo 0.1.
    pub const fn earth() -> Self {
        Self {
            bottom_radius_km: 6360.0,
            top_radius_km: 6460.0,
            rayleigh_scattering_per_km: [5.802e-3, 13.558e-3, 33.1e-3],
            rayleigh_scale_height_km: 8.0,
            mie_scattering_per_km: 3.996e-3,
            mie_extinction_per_km: 4.40e-3,
            mie_scale_height_km: 1.2,
            mie_g: 0.8,
            ozone_absorption_per_km: [0.650e-3, 1.881e-3, 0.085e-3],
            ozone_centre_km: 25.0,
            ozone_half_width_km: 15.0,
            ground_albedo: [0.1; 3],
            sun_angular_radius_rad: 0.004675,
        }
    }

    /// The medium `altitude_km` above the ground.
    pub fn medium(&self, altitude_km: f64) -> Medium {
        let rayleigh = (-altitude_km / self.rayleigh_scale_height_km).exp();
        let mie = (-altitude_km / self.mie_scale_height_km).exp();
        let ozone = (1.0 - (altitude_km - self.ozone_centre_km).abs() / self.ozone_half_width_km).max(0.0);
        let rayleigh_scattering = self.rayleigh_scattering_per_km.map(|s| s * rayleigh);
        let mie_extinction = self.mie_extinction_per_km * mie;
        let extinction = std::array::from_fn(|c| {
            rayleigh_scattering[c] + mie_extinction + self.ozone_absorption_per_km[c] * ozone
        });
        Medium { rayleigh_scattering, mie_scattering: self.mie_scattering_per_km * mie, extinction }
    }

    /// Altitude of a point `p_km` from the Earth's centre, km.
    pub fn altitude_km(&self, p_km: DVec3) -> f64 {
        p_km.length() - self.bottom_radius_km
    }

    /// Where a ray from `origin_km` along the unit `dir` leaves the air, km along it: at the
    /// ground where it meets it first (`Exit::Ground`), else at the top. `None` where it never
    /// enters the air (from outside, passing by).
    pub fn exit(&self, origin_km: DVec3, dir: DVec3) -> Option<Exit> {
        if let Some(t) = nearest_hit(origin_km, dir, self.bottom_radius_km) {
            return Some(Exit::Ground(t));
        }
        far_hit(origin_km, dir, self.top_radius_km).map(Exit::Top)
    }

    /// The segment of the ray inside the air, km along it, and whether it ends on the ground.
    pub fn segment(&self, origin_km: DVec3, dir: DVec3) -> Option<(f64, f64, bool)> {
        let start = if origin_km.length() <= self.top_radius_km {
            0.0
        } else {
            nearest_hit(origin_km, dir, self.top_radius_km)?
        };
        match self.exit(origin_km, dir)? {
            Exit::Ground(t) => Some((start, t, true)),
            Exit::Top(t) => Some((start, t, false)),
        }
    }
}

/// Where a ray leaves the air.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exit {
    /// On the ground, km along the ray.
    Ground(f64),
    /// Through the top, km along the ray.
    Top(f64),
}

/// Rayleigh's phase function for the cosine `nu` between the light's and the view's directions,
/// per steradian.
pub fn rayleigh_phase(nu: f64) -> f64 {
    3.0 / (16.0 * std::f64::consts::PI) * (1.0 + nu * nu)
}

/// Cornette and Shanks' phase function (Bruneton's choice for the aerosols), per steradian.
pub fn mie_phase(nu: f64, g: f64) -> f64 {
    let k = 3.0 / (8.0 * std::f64::consts::PI) * (1.0 - g * g) / (2.0 + g * g);
    k * (1.0 + nu * nu) / (1.0 + g * g - 2.0 * g * nu).powf(1.5)
}

/// The first two Legendre moments of a phase function of the scattering angle's cosine, per
/// steradian: k₁ = ⟨ν⟩ (the mean cosine) and k₂ = ⟨P₂(ν)⟩ over the sphere. Scattering light
/// whose angular distribution is a spherical harmonic of degree l multiplies it by k_l (the
/// Funk–Hecke theorem): what the multiple-scattering table's expansion weighs its degrees by.
/// Midpoint rule in ν over 4,000 bands (the Mie peak at g = 0.8 is 0.3 wide in ν).
pub fn legendre_moments(phase: impl Fn(f64) -> f64) -> [f64; 2] {
    let bands = 4_000;
    let width = 2.0 / bands as f64;
    (0..bands).fold([0.0; 2], |[k1, k2], i| {
        let nu = -1.0 + (i as f64 + 0.5) * width;
        let weight = phase(nu) * 2.0 * std::f64::consts::PI * width;
        [k1 + weight * nu, k2 + weight * (1.5 * nu * nu - 0.5)]
    })
}

/// The nearest positive distance along the unit `dir` from `origin` to a sphere of `radius`
/// around the origin, where the ray enters or leaves it ahead.
pub fn nearest_hit(origin: DVec3, dir: DVec3, radius: f64) -> Option<f64> {
    let (near, far) = sphere_hits(origin, dir, radius)?;
    [near, far].into_iter().find(|&t| t > 0.0)
}

/// The farthest positive distance from `origin` along the unit `dir` to a sphere of `radius`.
pub fn far_hit(origin: DVec3, dir: DVec3, radius: f64) -> Option<f64> {
    let (_, far) = sphere_hits(origin, dir, radius)?;
    (far > 0.0).then_some(far)
}

/// Both distances along the ray to a sphere around the origin, nearer first, or `None` where
/// it misses. Written as the numerically stable quadratic: no cancellation for rays that start
/// on the sphere.
fn sphere_hits(origin: DVec3, dir: DVec3, radius: f64) -> Option<(f64, f64)> {
    let b = origin.dot(dir);
    let c = origin.length_squared() - radius * radius;
    let discriminant = b * b - c;
    if discriminant < 0.0 {
        return None;
    }
    let q = -b - discriminant.sqrt().copysign(b);
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q, c / q) };
    Some((t0.min(t1), t0.max(t1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phase_functions_integrate_to_one_over_the_sphere() {
        // Midpoint rule in cos θ over 20,000 bands: the Mie peak at g = 0.8 is 0.3 wide in ν.
        let bands = 20_000;
        let integral = |phase: &dyn Fn(f64) -> f64| {
            (0..bands)
                .map(|i| {
                    let nu = -1.0 + (i as f64 + 0.5) * 2.0 / bands as f64;
                    phase(nu) * 2.0 * std::f64::consts::PI * 2.0 / bands as f64
                })
                .sum::<f64>()
        };
        assert!((integral(&rayleigh_phase) - 1.0).abs() < 1e-6);
        assert!((integral(&|nu| mie_phase(nu, 0.8)) - 1.0).abs() < 1e-4);
    }

    /// The moments by quadrature against their closed forms.
    const PUBLISHED_OFF: f64 = 1e-4;

    #[test]
    fn the_phase_functions_moments_are_the_published_ones() {
        // Rayleigh's phase is (1 + ν²) 3/16π: no mean cosine, k₂ = 1/10.
        let [k1, k2] = legendre_moments(rayleigh_phase);
        assert!(k1.abs() < PUBLISHED_OFF && (k2 - 0.1).abs() < PUBLISHED_OFF, "{k1} {k2}");
        // Cornette and Shanks (1992) give their function's mean cosine as 3g(4 + g²) / 5(2 + g²).
        for g in [0.0, 0.5, 0.8] {
            let [k1, _] = legendre_moments(|nu| mie_phase(nu, g));
            let published = 3.0 * g * (4.0 + g * g) / (5.0 * (2.0 + g * g));
            assert!((k1 - published).abs() < PUBLISHED_OFF, "g {g}: {k1} against {published}");
        }
    }

    #[test]
    fn rays_leave_the_air_where_the_geometry_says() {
        let air = Atmosphere::earth();
        let ground = DVec3::new(0.0, 0.0, air.bottom_radius_km + 1e-3);
        let up = air.exit(ground, DVec3::Z).unwrap();
        assert!(matches!(up, Exit::Top(t) if (t - 99.999).abs() < 1e-9));
        assert!(matches!(air.exit(ground, -DVec3::Z).unwrap(), Exit::Ground(t) if (t - 1e-3).abs() < 1e-9));
        // Level from the ground: the top's tangent-free chord, √(top² − r²).
        let level = air.exit(ground, DVec3::X).unwrap();
        let expected = (air.top_radius_km.powi(2) - ground.length_squared()).sqrt();
        assert!(matches!(level, Exit::Top(t) if (t - expected).abs() < 1e-9));
        // From space, the segment starts at the top.
        let orbit = DVec3::new(0.0, 0.0, air.bottom_radius_km + 400.0);
        let (start, end, ground_hit) = air.segment(orbit, -DVec3::Z).unwrap();
        assert!((start - 300.0).abs() < 1e-9 && (end - 400.0).abs() < 1e-9 && ground_hit);
        assert!(air.segment(orbit, DVec3::Z).is_none());
    }

    #[test]
    fn the_media_peak_where_the_model_says() {
        let air = Atmosphere::earth();
        let ground = air.medium(0.0);
        assert_eq!(ground.rayleigh_scattering, air.rayleigh_scattering_per_km);
        // At the ozone peak its absorption is whole, 15 km off it none.
        let peak = air.medium(25.0);
        let rayleigh_and_mie =
            peak.rayleigh_scattering[1] + air.mie_extinction_per_km * (-25.0f64 / 1.2).exp();
        assert!((peak.extinction[1] - rayleigh_and_mie - air.ozone_absorption_per_km[1]).abs() < 1e-15);
        let above = air.medium(40.0);
        let no_ozone = above.rayleigh_scattering[1] + air.mie_extinction_per_km * (-40.0f64 / 1.2).exp();
        assert!((above.extinction[1] - no_ozone).abs() < 1e-15);
    }
}
