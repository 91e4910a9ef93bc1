//! Twin of the light the atmosphere gives the lit passes: the sky-irradiance table
//! (`irradiance_lut`), the frame's daylight balance (`daylight_balance`, `balanced`), the light
//! at a point (`light_at`) and the air between it and the camera
//! (`Volume::air_between`, `air_marched` from high up, `through_air`), as `shaders/atmosphere.wgsl` and
//! `shaders/shared/air.wgsl` compute them, in f32. The volume's filtering is the one place the
//! twin cannot follow the GPU's arithmetic exactly (the sampler's weights are the adapter's):
//! it filters trilinearly in f32.

use glam::{Vec2, Vec3, Vec4Swizzles};

use super::{Lut, Tables, Volume, aerial_distance, grid_direction, mix, ray_segment};
use crate::gpu::gpu_types::AtmosphereUniforms;
use crate::gpu::layout::{
    DAYLIGHT_SUN_COS, IRRADIANCE_DIRECTIONS_SIDE, PI, SCENE_LIGHT_MAX, SKY_MARCHED_ABOVE_KM, SKY_VIEW_STEPS,
};

/// `SunAndSky`: the light at a point per unit of the sun's irradiance above the air.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunAndSky {
    /// The sun's share that reaches it (0 where the Earth hides the sun).
    pub sun: Vec3,
    /// The sky's light on a level surface there.
    pub sky: Vec3,
    /// The point's zenith, camera-relative.
    pub up: Vec3,
}

impl Tables<'_> {
    /// `irradiance_lut`: the sky's light on a level surface per (sun's zenith cosine, altitude),
    /// `size` texels.
    pub fn irradiance_lut(&self, size: [u32; 2]) -> Lut {
        let m = &self.model;
        let side = IRRADIANCE_DIRECTIONS_SIDE;
        Lut::made(size, |texel| {
            let (r, mu_sun) = m.multiple_r_mu_sun(texel, size);
            let sun = Vec3::new((1.0 - mu_sun * mu_sun).max(0.0).sqrt(), 0.0, mu_sun);
            let mut gathered = Vec3::ZERO;
            for i in 0..side * side {
                let dir = grid_direction(i, side, 0.0, 1.0);
                gathered += self.in_scattered(r, dir.z, mu_sun, dir.dot(sun)) * dir.z;
            }
            gathered * 2.0 * PI / (side * side) as f32
        })
    }

    /// `daylight_balance`: per channel, 1 over the light on level ground at sea level under a sun
    /// `DAYLIGHT_SUN_COS` from the zenith, sun and sky.
    pub fn daylight_balance(&self, irradiance: &Lut) -> Vec3 {
        let r = self.model.bottom();
        let sun = self.sun_transmittance(r, DAYLIGHT_SUN_COS) * DAYLIGHT_SUN_COS;
        let sky = irradiance.read(self.model.multiple_unit(r, DAYLIGHT_SUN_COS));
        Vec3::ONE / (sun + sky)
    }

    /// `light_at`: the light at `rel_m` from the camera (metres), the air's centre below the
    /// camera along its zenith.
    pub fn light_at(&self, irradiance: &Lut, rel_m: Vec3) -> SunAndSky {
        let (m, u) = (&self.model, self.model.u);
        let from_centre_km = rel_m * 0.001 + Vec3::from_slice(&u.up[..3]) * u.up[3];
        let length_km = from_centre_km.length();
        let up = from_centre_km / length_km;
        let r = length_km.clamp(m.bottom(), m.top());
        let mu_sun = up.dot(glam::Vec4::from(u.sun_dir).xyz()).clamp(-1.0, 1.0);
        let sky = irradiance.read(m.multiple_unit(r, mu_sun));
        SunAndSky { sun: self.sun_transmittance(r, mu_sun), sky, up }
    }

    /// `air_marched`: (in-scattered light, transmittance) between the camera and a point at
    /// `rel_m` (metres), marched from the point back towards the camera up to where the ray
    /// entered the air.
    pub fn air_marched(&self, rel_m: Vec3) -> (Vec3, Vec3) {
        let (m, u) = (&self.model, self.model.u);
        let r = u.up[3];
        let distance_km = rel_m.length() * 0.001;
        let dir = rel_m * (0.001 / distance_km.max(1e-9));
        let (mu, nu) = (dir.dot(Vec3::from_slice(&u.up[..3])), dir.dot(glam::Vec4::from(u.sun_dir).xyz()));
        let top = m.top();
        let mut entry = 0.0;
        if r > top {
            let inside = r * r * (mu * mu - 1.0) + top * top;
            if mu >= 0.0 || inside < 0.0 {
                return (Vec3::ZERO, Vec3::ONE);
            }
            entry = -r * mu - inside.sqrt();
        }
        let length = (distance_km - entry).max(0.0);
        let (rayleigh, mie) = (3.0 / (16.0 * PI) * (1.0 + nu * nu), m.mie_phase(nu));
        let (mut light, mut seen) = (Vec3::ZERO, Vec3::ONE);
        for k in 0..SKY_VIEW_STEPS {
            let (middle, dt) = ray_segment(k, SKY_VIEW_STEPS, length);
            let s = self.ray_step_at(r, mu, u.radii[3], nu, distance_km - middle, dt);
            light = self.sky_source(&s, nu, rayleigh, mie) * s.kept + s.through * light;
            seen *= s.through;
        }
        (light, seen)
    }
}

/// `balanced`: a radiance times π as the frame holds it, balanced by `daylight` (white ground in
/// daylight is 1), within the colour target's f16.
pub fn balanced(radiance_pi: Vec3, daylight: Vec3) -> Vec3 {
    (radiance_pi * daylight).max(Vec3::ZERO).min(Vec3::splat(SCENE_LIGHT_MAX))
}

impl Volume {
    fn texel(&self, set: &[[f32; 4]], [x, y, z]: [u32; 3]) -> Vec3 {
        let [w, h, _] = self.size;
        Vec3::from_slice(&set[((z * h + y) * w + x) as usize][..3])
    }

    /// A clamp-to-edge trilinear sample of `set` at texture coordinates `at` (texel centres at
    /// (i + ½) / n), as a linear sampler reads it.
    fn sample(&self, set: &[[f32; 4]], at: Vec3) -> Vec3 {
        let n = Vec3::new(self.size[0] as f32, self.size[1] as f32, self.size[2] as f32);
        let x = (at * n - 0.5).clamp(Vec3::ZERO, n - 1.0);
        let base = x.floor().min(n - 2.0).max(Vec3::ZERO);
        let f = x - base;
        let [bx, by, bz] = [base.x as u32, base.y as u32, base.z as u32];
        let corner = |dx: u32, dy: u32, dz: u32| {
            let [mx, my, mz] = self.size.map(|s| s - 1);
            self.texel(set, [(bx + dx).min(mx), (by + dy).min(my), (bz + dz).min(mz)])
        };
        let plane = |dz: u32| {
            mix(
                mix(corner(0, 0, dz), corner(1, 0, dz), f.x),
                mix(corner(0, 1, dz), corner(1, 1, dz), f.x),
                f.y,
            )
        };
        mix(plane(0), plane(1), f.z)
    }

    /// `air_between`: (in-scattered light, transmittance) between the camera and a point at
    /// `rel_m` (metres) of a view with uniforms `u`.
    pub fn air_between(&self, u: &AtmosphereUniforms, rel_m: Vec3) -> (Vec3, Vec3) {
        let clip = glam::Mat4::from_cols_array_2d(&u.clip_from_view_world) * rel_m.extend(1.0);
        let ndc = clip.xy() / clip.w.max(1e-6);
        let distance_km = rel_m.length() * 0.001;
        let slices = u.aerial_slices as f32;
        let slice = (distance_km / u.aerial_far_km).sqrt() * slices - 1.0;
        let uv = Vec2::new(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y);
        let at = uv.extend((slice.clamp(0.0, slices - 1.0) + 0.5) / slices);
        let near = (distance_km / aerial_distance(u, 0)).clamp(0.0, 1.0);
        let (in_scattered, kept) = (self.sample(&self.inscatter, at), self.sample(&self.transmittance, at));
        (in_scattered * near, mix(Vec3::ONE, kept, near))
    }
}

/// `through_air`: a point's light `lit_pi` at `rel_m` as the frame holds it, through the air of `volume`
/// or marched with `tables` from high up (unless the uniforms turn aerial perspective off),
/// balanced by `daylight`.
pub fn through_air(tables: &Tables, volume: &Volume, daylight: Vec3, lit_pi: Vec3, rel_m: Vec3) -> Vec3 {
    let u = tables.model.u;
    if u.aerial_on == 0 {
        return balanced(lit_pi, daylight);
    }
    let (in_scattered, kept) = if u.up[3] - tables.model.bottom() > SKY_MARCHED_ABOVE_KM {
        tables.air_marched(rel_m)
    } else {
        volume.air_between(u, rel_m)
    };
    balanced(lit_pi * kept + PI * in_scattered, daylight)
}
