//! The atmosphere pass's twin: its tables and its sky, step for step as
//! `shaders/atmosphere.wgsl` and `shaders/shared/atmosphere.wgsl` compute them, in f32, from the
//! same `AtmosphereUniforms`. Tables are read between texels by hand in both, with the same
//! weights. `light` twins the sky's irradiance, the display and what the lit passes take from the
//! air (`shaders/shared/air.wgsl`). `tests/atmosphere.rs` holds the GPU to it; the brute-force
//! model (`atmosphere::brute`) judges them both.

pub mod light;
mod multiple;

use glam::{Vec2, Vec3, Vec4Swizzles};

use crate::gpu::gpu_types::AtmosphereUniforms;
use crate::gpu::layout::{AERIAL_SUBSTEPS, PI, SKY_MARCHED_ABOVE_KM, SKY_VIEW_STEPS, TRANSMITTANCE_STEPS};

/// One table: its size and texels, row by row (rgb used, a = 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Lut {
    /// Width and height, texels.
    pub size: [u32; 2],
    /// Texels, row by row.
    pub texels: Vec<[f32; 4]>,
}

impl Lut {
    fn made(size: [u32; 2], texel: impl Fn([u32; 2]) -> Vec3) -> Self {
        let texels = (0..size[1])
            .flat_map(|y| (0..size[0]).map(move |x| [x, y]))
            .map(|xy| texel(xy).extend(1.0).to_array())
            .collect();
        Self { size, texels }
    }

    fn load(&self, x: u32, y: u32) -> Vec3 {
        Vec3::from_slice(&self.texels[(y * self.size[0] + x) as usize][..3])
    }

    /// `read` within block `j` of `blocks` of equal width side by side (the shaders'
    /// `multiple_term`).
    pub fn read_block(&self, j: u32, blocks: u32, unit: Vec2) -> Vec3 {
        let width = self.size[0] / blocks;
        let last = Vec2::new((width - 1) as f32, (self.size[1] - 1) as f32);
        let x = unit.clamp(Vec2::ZERO, Vec2::ONE) * last;
        let base = [(x.x.floor() as u32).min(width - 2), (x.y.floor() as u32).min(self.size[1] - 2)];
        let f = x - Vec2::new(base[0] as f32, base[1] as f32);
        let x0 = j * width + base[0];
        let a = self.load(x0, base[1]);
        let b = self.load(x0 + 1, base[1]);
        let c = self.load(x0, base[1] + 1);
        let d = self.load(x0 + 1, base[1] + 1);
        mix(mix(a, b, f.x), mix(c, d, f.x), f.y)
    }

    /// `lut_read`: bilinear between the texels around `unit`, the grid spanning the unit square.
    pub fn read(&self, unit: Vec2) -> Vec3 {
        self.read_block(0, 1, unit)
    }
}

fn mix(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a * (1.0 - t) + b * t
}

struct Medium {
    rayleigh_scattering: Vec3,
    mie_scattering: f32,
    extinction: Vec3,
}

struct RayStep {
    r: f32,
    mu: f32,
    mu_sun: f32,
    medium: Medium,
    kept: Vec3,
    through: Vec3,
}

/// The model's functions over one set of uniforms (the shared WGSL's free functions).
#[derive(Debug, Clone, Copy)]
pub struct Model<'a> {
    u: &'a AtmosphereUniforms,
}

impl<'a> Model<'a> {
    /// The model the uniforms describe.
    pub fn new(u: &'a AtmosphereUniforms) -> Self {
        Self { u }
    }

    fn bottom(&self) -> f32 {
        self.u.radii[0]
    }

    fn top(&self) -> f32 {
        self.u.radii[1]
    }

    fn medium(&self, altitude_km: f32) -> Medium {
        let u = self.u;
        let rayleigh = (-altitude_km / u.rayleigh[3]).exp();
        let mie = (-altitude_km / u.mie[2]).exp();
        let ozone = (1.0 - (altitude_km - u.ozone[3]).abs() / u.albedo[3]).max(0.0);
        let rayleigh_scattering = Vec3::from_slice(&u.rayleigh[..3]) * rayleigh;
        let extinction = rayleigh_scattering + u.mie[1] * mie + Vec3::from_slice(&u.ozone[..3]) * ozone;
        Medium { rayleigh_scattering, mie_scattering: u.mie[0] * mie, extinction }
    }

    fn mie_phase(&self, nu: f32) -> f32 {
        let g = self.u.mie[3];
        let k = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
        k * (1.0 + nu * nu) / (1.0 + g * g - 2.0 * g * nu).powf(1.5)
    }

    fn distance_to_top(&self, r: f32, mu: f32) -> f32 {
        let top = self.top();
        (-r * mu + (r * r * (mu * mu - 1.0) + top * top).max(0.0).sqrt()).max(0.0)
    }

    fn distance_to_bottom(&self, r: f32, mu: f32) -> f32 {
        let bottom = self.bottom();
        (-r * mu - (r * r * (mu * mu - 1.0) + bottom * bottom).max(0.0).sqrt()).max(0.0)
    }

    /// Whether a ray from radius `r` at zenith cosine `mu` meets the ground.
    pub fn hits_ground(&self, r: f32, mu: f32) -> bool {
        let bottom = self.bottom();
        mu < 0.0 && r * r * (mu * mu - 1.0) + bottom * bottom >= 0.0
    }

    fn radius_along(&self, r: f32, mu: f32, t: f32) -> f32 {
        (t * t + 2.0 * r * mu * t + r * r).sqrt().max(self.bottom())
    }

    fn transmittance_unit(&self, r: f32, mu: f32) -> Vec2 {
        let (bottom, top) = (self.bottom(), self.top());
        let h = (top * top - bottom * bottom).sqrt();
        let rho = (r * r - bottom * bottom).max(0.0).sqrt();
        let d = self.distance_to_top(r, mu);
        let d_min = top - r;
        let d_max = rho + h;
        Vec2::new((d - d_min) / (d_max - d_min), rho / h)
    }

    fn transmittance_r_mu(&self, unit: Vec2) -> (f32, f32) {
        let (bottom, top) = (self.bottom(), self.top());
        let h = (top * top - bottom * bottom).sqrt();
        let rho = h * unit.y;
        let r = (rho * rho + bottom * bottom).sqrt();
        let d_min = top - r;
        let d_max = rho + h;
        let d = d_min + unit.x * (d_max - d_min);
        let mu = if d > 0.0 { ((h * h - rho * rho - d * d) / (2.0 * r * d)).clamp(-1.0, 1.0) } else { 1.0 };
        (r, mu)
    }

    /// `multiple_unit`: x the sun's zenith cosine as a signed square root, y the altitude.
    fn multiple_unit(&self, r: f32, mu_sun: f32) -> Vec2 {
        let x = 0.5 + 0.5 * mu_sun.signum() * mu_sun.abs().sqrt();
        Vec2::new(x, (r - self.bottom()) / (self.top() - self.bottom()))
    }

    /// `multiple_r_mu_sun`: (r, μ_sun) of a texel of a table in the multiple-scattering table's
    /// parametrisation.
    fn multiple_r_mu_sun(&self, texel: [u32; 2], size: [u32; 2]) -> (f32, f32) {
        let unit = lut_unit(texel, size);
        let s = 2.0 * unit.x - 1.0;
        (self.bottom() + unit.y * (self.top() - self.bottom()), s * s.abs())
    }

    fn horizon_zenith(&self, r: f32) -> f32 {
        PI - (self.bottom() / r).clamp(0.0, 1.0).asin()
    }

    fn sky_view_unit(&self, r: f32, view_zenith: f32, azimuth: f32) -> Vec2 {
        let horizon = self.horizon_zenith(r);
        let y = if view_zenith < horizon {
            0.5 - 0.5 * (1.0 - view_zenith / horizon).max(0.0).sqrt()
        } else {
            0.5 + 0.5 * ((view_zenith - horizon) / (PI - horizon)).max(0.0).sqrt()
        };
        Vec2::new((azimuth / PI).clamp(0.0, 1.0).sqrt(), y)
    }

    fn sky_view_angles(&self, r: f32, unit: Vec2) -> (f32, f32) {
        let horizon = self.horizon_zenith(r);
        let zenith = if unit.y < 0.5 {
            let s = 1.0 - 2.0 * unit.y;
            horizon * (1.0 - s * s)
        } else {
            let s = 2.0 * unit.y - 1.0;
            horizon + (PI - horizon) * s * s
        };
        (zenith, PI * unit.x * unit.x)
    }
}

fn ray_segment(k: u32, steps: u32, length: f32) -> (f32, f32) {
    let n = steps as f32;
    let a = k as f32 / n;
    let b = (k + 1) as f32 / n;
    let m = (k as f32 + 0.5) / n;
    (length * m * m, length * (b * b - a * a))
}

/// `grid_direction`: direction `i` of a `side` × `side` grid even in azimuth and in the zenith
/// cosine, which runs from `mu_from` to `mu_to`, cell centres.
fn grid_direction(i: u32, side: u32, mu_from: f32, mu_to: f32) -> Vec3 {
    let azimuth = 2.0 * PI * ((i % side) as f32 + 0.5) / side as f32;
    let mu = mu_from + (mu_to - mu_from) * ((i / side) as f32 + 0.5) / side as f32;
    let sin_theta = (1.0 - mu * mu).max(0.0).sqrt();
    Vec3::new(sin_theta * azimuth.cos(), sin_theta * azimuth.sin(), mu)
}

fn lut_unit(texel: [u32; 2], size: [u32; 2]) -> Vec2 {
    Vec2::new(texel[0] as f32 / (size[0] - 1) as f32, texel[1] as f32 / (size[1] - 1) as f32)
}

/// `transmittance_lut`.
pub fn transmittance_lut(u: &AtmosphereUniforms) -> Lut {
    let model = Model::new(u);
    Lut::made(u.transmittance_size, |texel| {
        let (r, mu) = model.transmittance_r_mu(lut_unit(texel, u.transmittance_size));
        let length = model.distance_to_top(r, mu);
        let mut depth = Vec3::ZERO;
        for k in 0..TRANSMITTANCE_STEPS {
            let (t, dt) = ray_segment(k, TRANSMITTANCE_STEPS, length);
            let altitude = model.radius_along(r, mu, t) - model.bottom();
            depth += model.medium(altitude).extinction * dt;
        }
        (-depth).exp()
    })
}

/// The tables a sky is read from, with the model they were made for.
#[derive(Debug, Clone, Copy)]
pub struct Tables<'a> {
    /// The model.
    pub model: Model<'a>,
    /// The transmittance table.
    pub transmittance: &'a Lut,
    /// The multiple-scattering table (`None` while it is being made).
    pub multiple: Option<&'a Lut>,
}

impl Tables<'_> {
    /// `sun_transmittance`: the transmittance table's share of light from radius `r` at zenith
    /// cosine `mu_sun` to the top (0 where the ground is in the way).
    pub fn sun_transmittance(&self, r: f32, mu_sun: f32) -> Vec3 {
        if self.model.hits_ground(r, mu_sun) {
            return Vec3::ZERO;
        }
        self.transmittance.read(self.model.transmittance_unit(r, mu_sun))
    }

    fn ray_length(&self, r: f32, mu: f32) -> f32 {
        let m = &self.model;
        if m.hits_ground(r, mu) { m.distance_to_bottom(r, mu) } else { m.distance_to_top(r, mu) }
    }

    /// `ray_step`.
    #[allow(clippy::too_many_arguments, reason = "the shader's `ray_step`, argument for argument")]
    fn ray_step(&self, r: f32, mu: f32, mu_sun: f32, nu: f32, k: u32, steps: u32, length: f32) -> RayStep {
        let (t, dt) = ray_segment(k, steps, length);
        self.ray_step_at(r, mu, mu_sun, nu, t, dt)
    }

    /// `ray_step_at`.
    fn ray_step_at(&self, r: f32, mu: f32, mu_sun: f32, nu: f32, t: f32, dt: f32) -> RayStep {
        let m = &self.model;
        let r_t = m.radius_along(r, mu, t);
        let mu_t = ((r * mu + t) / r_t).clamp(-1.0, 1.0);
        let mu_sun_t = ((r * mu_sun + t * nu) / r_t).clamp(-1.0, 1.0);
        let medium = m.medium(r_t - m.bottom());
        let through = (-medium.extinction * dt).exp();
        let kept = (Vec3::ONE - through) / medium.extinction.max(Vec3::splat(1e-12));
        RayStep { r: r_t, mu: mu_t, mu_sun: mu_sun_t, medium, kept, through }
    }

    /// `sky_source`.
    fn sky_source(&self, s: &RayStep, nu: f32, rayleigh: f32, mie: f32) -> Vec3 {
        let scattering = s.medium.rayleigh_scattering + s.medium.mie_scattering;
        self.sun_transmittance(s.r, s.mu_sun)
            * (s.medium.rayleigh_scattering * rayleigh + s.medium.mie_scattering * mie)
            + self.multiple_scattering(s.r, s.mu, s.mu_sun, nu) * scattering
    }

    /// `aerial_perspective_lut`, its texels rounded to f16 as the pass stores them.
    pub fn aerial_volume(&self) -> Volume {
        let m = &self.model;
        let u = m.u;
        let ([w, h], slices) = (u.aerial_size, u.aerial_slices);
        let texels = (w * h * slices) as usize;
        let mut volume = Volume {
            size: [w, h, slices],
            inscatter: vec![[0.0; 4]; texels],
            transmittance: vec![[0.0; 4]; texels],
        };
        let world_from_clip = glam::Mat4::from_cols_array_2d(&u.view_world_from_clip);
        let (up, sun) = (Vec3::from_slice(&u.up[..3]), Vec3::from_slice(&u.sun_dir[..3]));
        // From the camera itself, above the air or not.
        let (r, mu_sun) = (u.up[3], u.radii[3]);
        let stored = |v: Vec3| v.extend(1.0).to_array().map(|c| half::f16::from_f32(c).to_f32());
        for y in 0..h {
            for x in 0..w {
                let ndc = Vec2::new(
                    (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                    1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
                );
                let near = world_from_clip * glam::Vec4::new(ndc.x, ndc.y, 1.0, 1.0);
                let dir = (near.xyz() / near.w).normalize();
                let (mu, nu) = (dir.dot(up).clamp(-1.0, 1.0), dir.dot(sun));
                let (rayleigh, mie) = (3.0 / (16.0 * PI) * (1.0 + nu * nu), m.mie_phase(nu));
                let (mut seen, mut light, mut t) = (Vec3::ONE, Vec3::ZERO, 0.0f32);
                for z in 0..slices {
                    let end = aerial_distance(u, z);
                    let dt = (end - t) / AERIAL_SUBSTEPS as f32;
                    for k in 0..AERIAL_SUBSTEPS {
                        let s = self.ray_step_at(r, mu, mu_sun, nu, t + (k as f32 + 0.5) * dt, dt);
                        light += seen * self.sky_source(&s, nu, rayleigh, mie) * s.kept;
                        seen *= s.through;
                    }
                    t = end;
                    let i = ((z * h + y) * w + x) as usize;
                    volume.inscatter[i] = stored(light);
                    volume.transmittance[i] = stored(seen);
                }
            }
        }
        volume
    }

    /// `in_scattered`: the sky's light along a ray from radius `r` at zenith cosine `mu`, the sun
    /// at zenith cosine `mu_sun` and cosine `nu` with the ray (unrounded: no table holds it).
    pub fn in_scattered(&self, r: f32, mu: f32, mu_sun: f32, nu: f32) -> Vec3 {
        let length = self.ray_length(r, mu);
        let rayleigh = 3.0 / (16.0 * PI) * (1.0 + nu * nu);
        let mie = self.model.mie_phase(nu);
        let (mut seen, mut radiance) = (Vec3::ONE, Vec3::ZERO);
        for k in 0..SKY_VIEW_STEPS {
            let s = self.ray_step(r, mu, mu_sun, nu, k, SKY_VIEW_STEPS, length);
            radiance += seen * self.sky_source(&s, nu, rayleigh, mie) * s.kept;
            seen *= s.through;
        }
        radiance
    }

    /// `sky_view_lut` (the tables with the multiple-scattering one), its texels rounded to f16
    /// as the pass stores them.
    pub fn sky_view_lut(&self) -> Lut {
        let m = &self.model;
        let size = m.u.sky_view_size;
        let (r, mu_sun) = (m.u.radii[2], m.u.radii[3]);
        Lut::made(size, |texel| {
            let (zenith, azimuth) = m.sky_view_angles(r, lut_unit(texel, size));
            let mu = zenith.cos();
            let nu = zenith.sin() * azimuth.cos() * (1.0 - mu_sun * mu_sun).max(0.0).sqrt() + mu * mu_sun;
            self.in_scattered(r, mu, mu_sun, nu).to_array().map(|v| half::f16::from_f32(v).to_f32()).into()
        })
    }

    /// `marched_sky`.
    pub fn marched_sky(&self, r: f32, mu: f32, mu_sun: f32, nu: f32) -> Vec3 {
        let top = self.model.top();
        if r <= top {
            return self.in_scattered(r, mu, mu_sun, nu);
        }
        let inside = r * r * (mu * mu - 1.0) + top * top;
        if mu >= 0.0 || inside < 0.0 {
            return Vec3::ZERO;
        }
        let entry = -r * mu - inside.sqrt();
        self.in_scattered(top, (r * mu + entry) / top, ((r * mu_sun + entry * nu) / top).clamp(-1.0, 1.0), nu)
    }

    fn disk_transmittance(&self, r: f32, mu: f32) -> Vec3 {
        let top = self.model.top();
        if r <= top {
            return self.sun_transmittance(r, mu);
        }
        let inside = r * r * (mu * mu - 1.0) + top * top;
        if mu >= 0.0 || inside < 0.0 {
            return Vec3::ONE;
        }
        let entry = -r * mu - inside.sqrt();
        self.sun_transmittance(top, (r * mu + entry) / top)
    }

    /// `sky_radiance`: the sky along the camera-relative unit `dir`, read from `sky_view` or
    /// marched.
    pub fn sky_radiance(&self, sky_view: &Lut, dir: Vec3) -> Vec3 {
        let m = &self.model;
        let r_view = m.u.up[3];
        let up = Vec3::from_slice(&m.u.up[..3]);
        let sun = glam::Vec4::from(m.u.sun_dir).xyz();
        let mu = dir.dot(up).clamp(-1.0, 1.0);
        let mut radiance = if r_view - m.bottom() > SKY_MARCHED_ABOVE_KM {
            self.marched_sky(r_view, mu, sun.dot(up).clamp(-1.0, 1.0), dir.dot(sun))
        } else {
            let r = m.u.radii[2];
            let across = dir - up * mu;
            let sun_across = sun - up * sun.dot(up);
            let lengths = across.length() * sun_across.length();
            let azimuth =
                if lengths > 1e-6 { (across.dot(sun_across) / lengths).clamp(-1.0, 1.0).acos() } else { 0.0 };
            sky_view.read(m.sky_view_unit(r, mu.acos(), azimuth))
        };
        let sun_radius = m.u.sun_dir[3];
        if dir.dot(sun) > sun_radius.cos() && !m.hits_ground(r_view, mu) {
            radiance += self.disk_transmittance(r_view, mu) / (PI * sun_radius * sun_radius);
        }
        radiance
    }

    /// `fs_sky`'s light for a direction as the frame holds it, balanced by `daylight`
    /// (`light::daylight_balance`).
    pub fn sky_colour(&self, sky_view: &Lut, dir: Vec3, daylight: Vec3) -> Vec3 {
        light::balanced(self.sky_radiance(sky_view, dir) * PI, daylight)
    }
}

/// `aerial_distance`: how far slice `z` of the aerial-perspective volume reaches, km.
pub fn aerial_distance(u: &AtmosphereUniforms, z: u32) -> f32 {
    let share = (z + 1) as f32 / u.aerial_slices as f32;
    u.aerial_far_km * share * share
}

/// The aerial-perspective volume: per tile and slice, the light the air scatters towards the
/// camera and the share it lets through, out to the slice's distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Volume {
    /// Tiles across, down, and slices.
    pub size: [u32; 3],
    /// In-scattered light per unit of the sun's irradiance, slice by slice, row by row.
    pub inscatter: Vec<[f32; 4]>,
    /// Transmittance, the same way.
    pub transmittance: Vec<[f32; 4]>,
}

/// All three tables of `u`, made as the pass makes them: (transmittance, multiple, sky view).
pub fn tables(u: &AtmosphereUniforms) -> (Lut, Lut, Lut) {
    let model = Model::new(u);
    let transmittance = transmittance_lut(u);
    let multiple = Tables { model, transmittance: &transmittance, multiple: None }.multiple_scattering_lut();
    let sky_view = Tables { model, transmittance: &transmittance, multiple: Some(&multiple) }.sky_view_lut();
    (transmittance, multiple, sky_view)
}
