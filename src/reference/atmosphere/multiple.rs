//! The multiple-scattering table's twin (`multiple_scattering_lut`, `multiple_scattering` in the
//! shaders): the light of every order above the first that a point of the air scatters towards a
//! view direction, per (altitude, sun zenith), as six terms of an expansion in the view direction.
//!
//! How it works. Hillaire (2020) gathers the light that reaches a point after one scattering from
//! 64 directions with an isotropic phase at both ends and sends it on isotropically: one value per
//! point, whatever the direction seen. The truth's higher orders depend on the direction (with the
//! sun at the zenith the isotropic value was 5 % to 20 % too bright, with the sun at 10° 6 % to
//! 30 % too dark: docs/atmosphere.md), so here the gathered light keeps its shape. It is
//! gathered from 256 directions with the true phases at its first scattering, projected on the real
//! spherical harmonics up to degree 2 that are even across the sun's vertical plane (1, z, x,
//! 3z² − 1, xz, x² − y², x towards the sun's azimuth, z up), and scattered on towards the view by
//! the phase functions' own degrees (Funk–Hecke: degree l is multiplied by the phase's Legendre
//! moment k_l, mixed by the share of Rayleigh and Mie scattering at that altitude). Rayleigh's
//! phase has no degree above 2, so its part is whole; Mie's forward peak is cut at degree 2. The
//! orders above the second stay Hillaire's isotropic series, the constant term over (1 − f).

use glam::Vec3;
use rayon::prelude::*;

use super::{Lut, Tables, grid_direction};
use crate::gpu::layout::{MULTIPLE_DIRECTIONS_SIDE, MULTIPLE_STEPS, MULTIPLE_TERMS, PI};

/// `multiple_basis_weight`: 1 / ∫ b² dω of each term's function over the sphere (`basis`), the
/// projection's weights.
fn basis_weight(j: usize) -> f32 {
    [1.0 / 4.0, 3.0 / 4.0, 3.0 / 4.0, 5.0 / 16.0, 15.0 / 4.0, 15.0 / 16.0][j] / PI
}

/// `multiple_basis_of`: the terms' functions of a unit direction in the frame whose x points to
/// the sun's azimuth and z up.
fn basis(d: Vec3) -> [f32; MULTIPLE_TERMS as usize] {
    [1.0, d.z, d.x, 3.0 * d.z * d.z - 1.0, d.x * d.z, d.x * d.x - d.y * d.y]
}

/// `multiple_basis`: the terms' functions of a view direction at zenith cosine `mu`, the sun at
/// zenith cosine `mu_sun` and cosine `nu` with it. With the sun at the zenith the frame's x is
/// any horizontal, and the terms that hold it are nought there.
fn view_basis(mu: f32, mu_sun: f32, nu: f32) -> [f32; MULTIPLE_TERMS as usize] {
    let sin_sun = (1.0 - mu_sun * mu_sun).max(0.0).sqrt();
    let ring = (1.0 - mu * mu).max(0.0).sqrt();
    let x = if sin_sun > 1e-4 { ((nu - mu * mu_sun) / sin_sun).clamp(-ring, ring) } else { 0.0 };
    basis(Vec3::new(x, (ring * ring - x * x).max(0.0).sqrt(), mu))
}

impl Tables<'_> {
    /// `multiple_scattering`: the higher orders' light per unit of scattering, from radius `r`
    /// towards a view at zenith cosine `mu`, the sun at `mu_sun` and cosine `nu` with the view.
    pub(super) fn multiple_scattering(&self, r: f32, mu: f32, mu_sun: f32, nu: f32) -> Vec3 {
        let Some(lut) = self.multiple else { return Vec3::ZERO };
        let unit = self.model.multiple_unit(r, mu_sun);
        let psi = view_basis(mu, mu_sun, nu)
            .iter()
            .enumerate()
            .fold(Vec3::ZERO, |sum, (j, b)| sum + lut.read_block(j as u32, MULTIPLE_TERMS, unit) * *b);
        psi.max(Vec3::ZERO)
    }

    /// `second_order`: the light reaching radius `r` from a direction at zenith cosine `mu`
    /// after one scattering (the true phases, the sun at `mu_sun` and cosine `nu` with the
    /// direction; the ground's Lambertian light where the ray ends on it), and the share of
    /// light the air scatters along it (Hillaire's f).
    fn second_order(&self, r: f32, mu: f32, mu_sun: f32, nu: f32) -> (Vec3, Vec3) {
        let m = &self.model;
        let length = self.ray_length(r, mu);
        let (rayleigh, mie) = (3.0 / (16.0 * PI) * (1.0 + nu * nu), m.mie_phase(nu));
        let (mut seen, mut radiance, mut scattered) = (Vec3::ONE, Vec3::ZERO, Vec3::ZERO);
        for k in 0..MULTIPLE_STEPS {
            let s = self.ray_step(r, mu, mu_sun, nu, k, MULTIPLE_STEPS, length);
            let source = s.medium.rayleigh_scattering * rayleigh + s.medium.mie_scattering * mie;
            radiance += seen * self.sun_transmittance(s.r, s.mu_sun) * source * s.kept;
            scattered += seen * (s.medium.rayleigh_scattering + s.medium.mie_scattering) * s.kept;
            seen *= s.through;
        }
        if m.hits_ground(r, mu) {
            let r_g = m.bottom();
            let mu_sun_g = ((r * mu_sun + length * nu) / r_g).clamp(-1.0, 1.0);
            let albedo = Vec3::from_slice(&m.u.albedo[..3]);
            radiance += seen * self.sun_transmittance(r_g, mu_sun_g) * mu_sun_g.max(0.0) * albedo / PI;
        }
        (radiance, scattered)
    }

    /// The terms of one (r, μ_sun): the gathered light's projection, each degree weighed by the
    /// phases' moment at that altitude, the constant term carrying the higher orders' series.
    fn multiple_terms(&self, r: f32, mu_sun: f32) -> [Vec3; MULTIPLE_TERMS as usize] {
        let m = &self.model;
        let sun = Vec3::new((1.0 - mu_sun * mu_sun).max(0.0).sqrt(), 0.0, mu_sun);
        let side = MULTIPLE_DIRECTIONS_SIDE;
        let (mut sums, mut scattered) = ([Vec3::ZERO; MULTIPLE_TERMS as usize], Vec3::ZERO);
        for i in 0..side * side {
            // Uniform over the sphere, each direction 4π / N steradians.
            let dir = grid_direction(i, side, 1.0, -1.0);
            let (radiance, share) = self.second_order(r, dir.z, mu_sun, dir.dot(sun));
            for (sum, b) in sums.iter_mut().zip(basis(dir)) {
                *sum += radiance * b;
            }
            scattered += share;
        }
        let n = (side * side) as f32;
        let medium = m.medium(r - m.bottom());
        let mie = Vec3::splat(medium.mie_scattering)
            / (medium.rayleigh_scattering + medium.mie_scattering).max(Vec3::splat(1e-12));
        let [rayleigh_k2, mie_k1, mie_k2, _] = m.u.phase_moments;
        let k = [
            Vec3::ONE / (Vec3::ONE - scattered / n),
            mie * mie_k1,
            (Vec3::ONE - mie) * rayleigh_k2 + mie * mie_k2,
        ];
        let degree = [0, 1, 1, 2, 2, 2];
        std::array::from_fn(|j| sums[j] * (4.0 * PI / n) * basis_weight(j) * k[degree[j]])
    }

    /// `multiple_scattering_lut` (the tables without one): its terms side by side, each block
    /// the settings' size.
    pub fn multiple_scattering_lut(&self) -> Lut {
        let m = &self.model;
        let size = m.u.multiple_size;
        // Each texel gathers 256 rays: in parallel, as the GPU does.
        let terms: Vec<_> = (0..size[0] * size[1])
            .into_par_iter()
            .map(|i| {
                let (r, mu_sun) = m.multiple_r_mu_sun([i % size[0], i / size[0]], size);
                self.multiple_terms(r, mu_sun)
            })
            .collect();
        Lut::made([size[0] * MULTIPLE_TERMS, size[1]], |[x, y]| {
            terms[(y * size[0] + x % size[0]) as usize][(x / size[0]) as usize]
        })
    }
}
