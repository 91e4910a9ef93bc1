// The atmosphere's model on the GPU (`atmosphere::Atmosphere`, Hillaire 2020): the media by
// altitude, the phase functions, the shell's ray geometry in (r, μ) form, and the look-up tables'
// parametrisations and reads. Kilometres around the Earth's centre. Twin:
// `reference::atmosphere`, step for step in f32.

struct AtmosphereUniforms {
    rayleigh: vec4<f32>,
    mie: vec4<f32>,
    phase_moments: vec4<f32>,
    ozone: vec4<f32>,
    albedo: vec4<f32>,
    radii: vec4<f32>,
    view_world_from_clip: mat4x4<f32>,
    clip_from_view_world: mat4x4<f32>,
    up: vec4<f32>,
    sun_dir: vec4<f32>,
    transmittance_size: vec2<u32>,
    multiple_size: vec2<u32>,
    sky_view_size: vec2<u32>,
    aerial_size: vec2<u32>,
    aerial_far_km: f32,
    aerial_slices: u32,
    aerial_on: u32,
    _pad: u32,
}

struct Medium {
    rayleigh_scattering: vec3<f32>,
    mie_scattering: f32,
    extinction: vec3<f32>,
}

fn bottom_km() -> f32 { return atmosphere.radii.x; }
fn top_km() -> f32 { return atmosphere.radii.y; }

fn medium_at(altitude_km: f32) -> Medium {
    let rayleigh = exp(-altitude_km / atmosphere.rayleigh.w);
    let mie = exp(-altitude_km / atmosphere.mie.z);
    let ozone = max(1.0 - abs(altitude_km - atmosphere.ozone.w) / atmosphere.albedo.w, 0.0);
    let rayleigh_scattering = atmosphere.rayleigh.xyz * rayleigh;
    let extinction = rayleigh_scattering + atmosphere.mie.y * mie + atmosphere.ozone.xyz * ozone;
    return Medium(rayleigh_scattering, atmosphere.mie.x * mie, extinction);
}

fn rayleigh_phase(nu: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + nu * nu);
}

fn mie_phase(nu: f32) -> f32 {
    let g = atmosphere.mie.w;
    let k = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
    return k * (1.0 + nu * nu) / pow(1.0 + g * g - 2.0 * g * nu, 1.5);
}

// Distance from radius r along a ray at cosine μ from the zenith to the top of the air.
fn distance_to_top(r: f32, mu: f32) -> f32 {
    let top = top_km();
    return max(-r * mu + sqrt(max(r * r * (mu * mu - 1.0) + top * top, 0.0)), 0.0);
}

fn distance_to_bottom(r: f32, mu: f32) -> f32 {
    let bottom = bottom_km();
    return max(-r * mu - sqrt(max(r * r * (mu * mu - 1.0) + bottom * bottom, 0.0)), 0.0);
}

fn hits_ground(r: f32, mu: f32) -> bool {
    let bottom = bottom_km();
    return mu < 0.0 && r * r * (mu * mu - 1.0) + bottom * bottom >= 0.0;
}

// Radius and zenith cosine t km along the ray from (r, μ) (Bruneton 2017's `r_d`, `mu_d`).
fn radius_along(r: f32, mu: f32, t: f32) -> f32 {
    return max(sqrt(t * t + 2.0 * r * mu * t + r * r), bottom_km());
}

// The k-th of `steps` segments of a ray `length` long, spaced as the square of their index so
// the dense air near the ray's start is sampled finely: (midpoint, length).
fn ray_segment(k: u32, steps: u32, length: f32) -> vec2<f32> {
    let n = f32(steps);
    let a = f32(k) / n;
    let b = f32(k + 1u) / n;
    let m = (f32(k) + 0.5) / n;
    return vec2<f32>(length * m * m, length * (b * b - a * a));
}

// What reaches radius r from the sun at zenith cosine `mu_sun` through the air: the
// transmittance table's share, none where the Earth is in the way. Reads the includer's
// `transmittance` table.
fn sun_transmittance(r: f32, mu_sun: f32) -> vec3<f32> {
    if hits_ground(r, mu_sun) {
        return vec3<f32>(0.0);
    }
    return lut_read(transmittance, atmosphere.transmittance_size, transmittance_unit(r, mu_sun));
}

// The multiple-scattering table's terms' functions of a unit direction in the frame whose x
// points to the sun's azimuth and z up: the real spherical harmonics up to degree 2 that are even
// across the sun's vertical plane (twin: `reference::atmosphere::multiple`).
fn multiple_basis_of(d: vec3<f32>) -> array<f32, MULTIPLE_TERMS> {
    return array<f32, MULTIPLE_TERMS>(1.0, d.z, d.x, 3.0 * d.z * d.z - 1.0, d.x * d.z, d.x * d.x - d.y * d.y);
}

// The same for a view at zenith cosine μ, the sun at zenith cosine `mu_sun` and cosine ν with it.
// With the sun at the zenith the frame's x is any horizontal, and the terms that hold it are
// nought there.
fn multiple_basis(mu: f32, mu_sun: f32, nu: f32) -> array<f32, MULTIPLE_TERMS> {
    let sin_sun = sqrt(max(1.0 - mu_sun * mu_sun, 0.0));
    let ring = sqrt(max(1.0 - mu * mu, 0.0));
    var x = 0.0;
    if sin_sun > 1e-4 {
        x = clamp((nu - mu * mu_sun) / sin_sun, -ring, ring);
    }
    return multiple_basis_of(vec3<f32>(x, sqrt(max(ring * ring - x * x, 0.0)), mu));
}

// The light of every order above the first that the air at radius r scatters towards a view at
// zenith cosine μ, per unit of scattering, the sun at zenith cosine `mu_sun` and cosine ν with
// the view: the table's terms at (r, μ_sun) times their functions of the view. Reads the
// includer's `multiple` table. Written out term by term, the texel and its weights found once:
// the lit passes march this per fragment from high up, where lavapipe pays for every address.
fn multiple_scattering(r: f32, mu: f32, mu_sun: f32, nu: f32) -> vec3<f32> {
    let size = atmosphere.multiple_size;
    let x = clamp(multiple_unit(r, mu_sun), vec2<f32>(0.0), vec2<f32>(1.0)) * vec2<f32>(size - 1u);
    let base = min(vec2<u32>(floor(x)), size - 2u);
    let f = x - vec2<f32>(base);
    let b = multiple_basis(mu, mu_sun, nu);
    let psi = multiple_term(base, f, 0u) * b[0] + multiple_term(base, f, 1u) * b[1] + multiple_term(base, f, 2u) * b[2]
        + multiple_term(base, f, 3u) * b[3] + multiple_term(base, f, 4u) * b[4] + multiple_term(base, f, 5u) * b[5];
    return max(psi, vec3<f32>(0.0));
}

// Term `term` of the multiple-scattering table between the texels from `base` on, weighed by `f`
// (`lut_read`'s reads and weights).
fn multiple_term(base: vec2<u32>, f: vec2<f32>, term: u32) -> vec3<f32> {
    let at = base + vec2<u32>(term * atmosphere.multiple_size.x, 0u);
    let a = textureLoad(multiple, at, 0).rgb;
    let b = textureLoad(multiple, at + vec2<u32>(1u, 0u), 0).rgb;
    let c = textureLoad(multiple, at + vec2<u32>(0u, 1u), 0).rgb;
    let d = textureLoad(multiple, at + vec2<u32>(1u, 1u), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// One segment of a ray from (r, μ) for the sun at zenith cosine `mu_sun` and cosine `nu` with
// the ray: the radius, the ray's and the sun's zenith cosines at its midpoint, the medium there, and the
// segment's integral of its own falling transmittance, ∫ e^(−σt) dt = (1 − e^(−σ dt)) / σ
// (Hillaire's energy-conserving step), with its transmittance e^(−σ dt).
struct RayStep {
    r: f32,
    mu: f32,
    mu_sun: f32,
    medium: Medium,
    kept: vec3<f32>,
    through: vec3<f32>,
}

fn ray_step(r: f32, mu: f32, mu_sun: f32, nu: f32, k: u32, steps: u32, length: f32) -> RayStep {
    let segment = ray_segment(k, steps, length);
    return ray_step_at(r, mu, mu_sun, nu, segment.x, segment.y);
}

// The segment `dt` long around `t` km along the ray.
fn ray_step_at(r: f32, mu: f32, mu_sun: f32, nu: f32, t: f32, dt: f32) -> RayStep {
    let r_t = radius_along(r, mu, t);
    let mu_t = clamp((r * mu + t) / r_t, -1.0, 1.0);
    let mu_sun_t = clamp((r * mu_sun + t * nu) / r_t, -1.0, 1.0);
    let medium = medium_at(r_t - bottom_km());
    let through = exp(-medium.extinction * dt);
    let kept = (vec3<f32>(1.0) - through) / max(medium.extinction, vec3<f32>(1e-12));
    return RayStep(r_t, mu_t, mu_sun_t, medium, kept, through);
}

// What a segment scatters towards the view per unit length: single scattering with the true
// phases (`rayleigh`, `mie` at the view's angle to the sun, whose cosine is ν) and the higher
// orders towards the view.
fn sky_source(s: RayStep, nu: f32, rayleigh: f32, mie: f32) -> vec3<f32> {
    let scattering = s.medium.rayleigh_scattering + s.medium.mie_scattering;
    return sun_transmittance(s.r, s.mu_sun) * (s.medium.rayleigh_scattering * rayleigh + s.medium.mie_scattering * mie)
        + multiple_scattering(s.r, s.mu, s.mu_sun, nu) * scattering;
}

// A radiance times π (what a white Lambertian surface sends under that irradiance) as the frame
// holds it: balanced for daylight by the includer's `daylight` (`daylight_balance`), so white
// ground in daylight is 1, and kept within the colour target's f16. The display pass exposes it
// and brings it into the display's range (`shaders/display.wgsl`).
fn balanced(radiance_pi: vec3<f32>) -> vec3<f32> {
    return min(max(radiance_pi * daylight.xyz, vec3<f32>(0.0)), vec3<f32>(SCENE_LIGHT_MAX));
}

// A table's texel grid spans the unit square corner to corner: texel (0, 0) is (0, 0), the last
// texel is (1, 1); read between texels bilinearly by hand, so the twin reads the same weights.
fn lut_unit(texel: vec2<u32>, size: vec2<u32>) -> vec2<f32> {
    return vec2<f32>(texel) / vec2<f32>(size - 1u);
}

fn lut_read(lut: texture_2d<f32>, size: vec2<u32>, unit: vec2<f32>) -> vec3<f32> {
    let x = clamp(unit, vec2<f32>(0.0), vec2<f32>(1.0)) * vec2<f32>(size - 1u);
    let base = min(vec2<u32>(floor(x)), size - 2u);
    let f = x - vec2<f32>(base);
    let a = textureLoad(lut, base, 0).rgb;
    let b = textureLoad(lut, base + vec2<u32>(1u, 0u), 0).rgb;
    let c = textureLoad(lut, base + vec2<u32>(0u, 1u), 0).rgb;
    let d = textureLoad(lut, base + vec2<u32>(1u, 1u), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// The transmittance table (Bruneton 2017): x the distance to the top between its least and its
// most at that radius (so the horizon lands on a texel edge's worth of resolution), y the
// radius by the distance to the horizon from the ground.
fn transmittance_unit(r: f32, mu: f32) -> vec2<f32> {
    let bottom = bottom_km();
    let top = top_km();
    let h = sqrt(top * top - bottom * bottom);
    let rho = sqrt(max(r * r - bottom * bottom, 0.0));
    let d = distance_to_top(r, mu);
    let d_min = top - r;
    let d_max = rho + h;
    return vec2<f32>((d - d_min) / (d_max - d_min), rho / h);
}

// (r, μ) of a point of the transmittance table's unit square.
fn transmittance_r_mu(unit: vec2<f32>) -> vec2<f32> {
    let bottom = bottom_km();
    let top = top_km();
    let h = sqrt(top * top - bottom * bottom);
    let rho = h * unit.y;
    let r = sqrt(rho * rho + bottom * bottom);
    let d_min = top - r;
    let d_max = rho + h;
    let d = d_min + unit.x * (d_max - d_min);
    var mu = 1.0;
    if d > 0.0 {
        mu = clamp((h * h - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
    }
    return vec2<f32>(r, mu);
}

// The multiple-scattering table: x the sun's zenith cosine from −1 to 1 as the signed square
// root of its magnitude (fine about the horizon, where twilight falls by orders of magnitude
// within a few degrees and a linear x would read the chord of that fall), y the altitude.
fn multiple_unit(r: f32, mu_sun: f32) -> vec2<f32> {
    return vec2<f32>(0.5 + 0.5 * sign(mu_sun) * sqrt(abs(mu_sun)), (r - bottom_km()) / (top_km() - bottom_km()));
}

// The zenith angle of the horizon seen from radius r (90° on the ground, more above it).
fn horizon_zenith(r: f32) -> f32 {
    return PI - asin(clamp(bottom_km() / r, 0.0, 1.0));
}

// The sky-view table, for a view at radius r: x the azimuth from the sun's vertical, 0 to π,
// as its square root (finer towards the sun), y the zenith angle, squared away from the
// horizon on both sides (finer at the horizon, where the sky changes fastest).
fn sky_view_unit(r: f32, view_zenith: f32, azimuth: f32) -> vec2<f32> {
    let horizon = horizon_zenith(r);
    var y = 0.0;
    if view_zenith < horizon {
        y = 0.5 - 0.5 * sqrt(max(1.0 - view_zenith / horizon, 0.0));
    } else {
        y = 0.5 + 0.5 * sqrt(max((view_zenith - horizon) / (PI - horizon), 0.0));
    }
    return vec2<f32>(sqrt(clamp(azimuth / PI, 0.0, 1.0)), y);
}

// (zenith, azimuth) of a point of the sky-view table's unit square at radius r.
fn sky_view_angles(r: f32, unit: vec2<f32>) -> vec2<f32> {
    let horizon = horizon_zenith(r);
    var zenith = 0.0;
    if unit.y < 0.5 {
        let s = 1.0 - 2.0 * unit.y;
        zenith = horizon * (1.0 - s * s);
    } else {
        let s = 2.0 * unit.y - 1.0;
        zenith = horizon + (PI - horizon) * s * s;
    }
    return vec2<f32>(zenith, PI * unit.x * unit.x);
}

// The distance from the camera, km, that slice z of the aerial-perspective volume holds the
// light out to: the volume's reach by the square of the slice's share, so near slices are short.
fn aerial_distance(z: u32) -> f32 {
    let share = f32(z + 1u) / f32(atmosphere.aerial_slices);
    return atmosphere.aerial_far_km * share * share;
}
