// The atmosphere pass (Hillaire 2020): three look-up tables made by compute, then the sky drawn
// behind everything from them.
// - `transmittance_lut`: per (r, μ), the share of light that crosses the air from there to its
//   top, by quadrature of the extinction (made when the atmosphere changes).
// - `multiple_scattering_lut`: per (altitude, sun's zenith cosine), the light of every order of
//   scattering above the first, as six terms of an expansion in the view direction: the light
//   reaching the point after one scattering, gathered from 256 directions with the true phases
//   (ground included), projected on the spherical harmonics up to degree 2 and scattered on by
//   the phases' Legendre moments; the orders above the second as Hillaire's geometric series of
//   the share the air scatters back, 1 / (1 − f), on the constant term (made when the atmosphere
//   changes; twin `reference::atmosphere::multiple`, which says why).
// - `sky_view_lut`: per view direction from the camera's altitude, the light the air scatters
//   towards it (single scattering with the true phases and the sun's transmittance from the
//   table, plus the higher orders towards it), up to the ground or the top (made each frame: it
//   depends on the camera's altitude and the sun).
// - `irradiance_lut`: per (altitude, sun's zenith cosine), the sky's light on a level surface,
//   gathered from the upper hemisphere (made when the atmosphere changes), which lights the
//   ground and the plants beside the sun (`shared/air.wgsl`); `daylight_balance` from it and
//   the transmittance, once: the frame's balance for daylight (`balanced`).
// - `vs_sky` with `fs_sky` or `fs_sky_marched`: where the depth is still the far plane
//   (reversed-Z 0), the sky from the sky-view table (or marched per pixel from high up), and the
//   sun's disk through the air.
// Radiances are per unit of the sun's irradiance above the air; the frame holds them balanced
// for daylight (`balanced`), as the ground and the plants are.

// Storage, not uniform: see `AtmospherePass::new`.
@group(0) @binding(0) var<storage, read> atmosphere: AtmosphereUniforms;
@group(0) @binding(1) var transmittance_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(2) var transmittance: texture_2d<f32>;
@group(0) @binding(3) var multiple_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var multiple: texture_2d<f32>;
@group(0) @binding(5) var sky_view_out: texture_storage_2d<rgba16float, write>;
@group(0) @binding(6) var sky_view: texture_2d<f32>;
@group(0) @binding(7) var sky_sampler: sampler;
@group(0) @binding(8) var aerial_inscatter_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(9) var aerial_transmittance_out: texture_storage_3d<rgba16float, write>;
@group(0) @binding(10) var irradiance_out: texture_storage_2d<rgba32float, write>;
@group(0) @binding(11) var irradiance: texture_2d<f32>;
@group(0) @binding(12) var<storage, read_write> daylight_out: vec4<f32>;
@group(0) @binding(13) var<uniform> daylight: vec4<f32>;

@compute @workgroup_size(ATMOSPHERE_WORKGROUP, ATMOSPHERE_WORKGROUP)
fn transmittance_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = atmosphere.transmittance_size;
    if any(id.xy >= size) {
        return;
    }
    let r_mu = transmittance_r_mu(lut_unit(id.xy, size));
    let length = distance_to_top(r_mu.x, r_mu.y);
    var depth = vec3<f32>(0.0);
    for (var k = 0u; k < TRANSMITTANCE_STEPS; k++) {
        let segment = ray_segment(k, TRANSMITTANCE_STEPS, length);
        let altitude = radius_along(r_mu.x, r_mu.y, segment.x) - bottom_km();
        depth += medium_at(altitude).extinction * segment.y;
    }
    textureStore(transmittance_out, id.xy, vec4<f32>(exp(-depth), 1.0));
}

// Where a ray from (r, μ) leaves the air: at the ground where it meets it, else at the top.
fn ray_length(r: f32, mu: f32) -> f32 {
    if hits_ground(r, mu) {
        return distance_to_bottom(r, mu);
    }
    return distance_to_top(r, mu);
}

// The light reaching radius r from a direction at zenith cosine μ after one scattering (the true
// phases, the sun at `mu_sun` and cosine ν with the direction; the ground's Lambertian light
// where the ray ends on it), and the share of light the air scatters along it (`scattered`,
// Hillaire's f).
struct SecondOrder {
    radiance: vec3<f32>,
    scattered: vec3<f32>,
}

fn second_order(r: f32, mu: f32, mu_sun: f32, nu: f32) -> SecondOrder {
    let length = ray_length(r, mu);
    let rayleigh = rayleigh_phase(nu);
    let mie = mie_phase(nu);
    var seen = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    var scattered = vec3<f32>(0.0);
    for (var k = 0u; k < MULTIPLE_STEPS; k++) {
        let s = ray_step(r, mu, mu_sun, nu, k, MULTIPLE_STEPS, length);
        let source = s.medium.rayleigh_scattering * rayleigh + s.medium.mie_scattering * mie;
        radiance += seen * sun_transmittance(s.r, s.mu_sun) * source * s.kept;
        scattered += seen * (s.medium.rayleigh_scattering + s.medium.mie_scattering) * s.kept;
        seen *= s.through;
    }
    if hits_ground(r, mu) {
        let r_g = bottom_km();
        let mu_sun_g = clamp((r * mu_sun + length * nu) / r_g, -1.0, 1.0);
        radiance += seen * sun_transmittance(r_g, mu_sun_g) * max(mu_sun_g, 0.0) * atmosphere.albedo.rgb / PI;
    }
    return SecondOrder(radiance, scattered);
}

// The sky's light along a ray: single scattering with the true phases, plus the higher orders
// towards the view, up to the ground or the top.
fn in_scattered(r: f32, mu: f32, mu_sun: f32, nu: f32) -> vec3<f32> {
    let length = ray_length(r, mu);
    let rayleigh = rayleigh_phase(nu);
    let mie = mie_phase(nu);
    var seen = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    for (var k = 0u; k < SKY_VIEW_STEPS; k++) {
        let s = ray_step(r, mu, mu_sun, nu, k, SKY_VIEW_STEPS, length);
        radiance += seen * sky_source(s, nu, rayleigh, mie) * s.kept;
        seen *= s.through;
    }
    return radiance;
}

// (r, μ_sun) of a texel of a table in the multiple-scattering table's parametrisation
// (`multiple_unit`: x the sun's zenith cosine as a signed square root, y the altitude).
fn multiple_r_mu_sun(texel: vec2<u32>, size: vec2<u32>) -> vec2<f32> {
    let unit = lut_unit(texel, size);
    let s = 2.0 * unit.x - 1.0;
    return vec2<f32>(bottom_km() + unit.y * (top_km() - bottom_km()), s * abs(s));
}

// Direction `i` of a `side` × `side` grid even in azimuth and in the zenith cosine, which runs
// from `mu_from` to `mu_to` (so even in solid angle), cell centres.
fn grid_direction(i: u32, side: u32, mu_from: f32, mu_to: f32) -> vec3<f32> {
    let azimuth = 2.0 * PI * (f32(i % side) + 0.5) / f32(side);
    let mu = mu_from + (mu_to - mu_from) * (f32(i / side) + 0.5) / f32(side);
    let sin_theta = sqrt(max(1.0 - mu * mu, 0.0));
    return vec3<f32>(sin_theta * cos(azimuth), sin_theta * sin(azimuth), mu);
}

// 1 / ∫ b² dω over the sphere of each of the terms' functions (`multiple_basis_of`).
fn multiple_basis_weight(j: u32) -> f32 {
    return array<f32, MULTIPLE_TERMS>(1.0 / 4.0, 3.0 / 4.0, 3.0 / 4.0, 5.0 / 16.0, 15.0 / 4.0, 15.0 / 16.0)[j] / PI;
}

@compute @workgroup_size(ATMOSPHERE_WORKGROUP, ATMOSPHERE_WORKGROUP)
fn multiple_scattering_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = atmosphere.multiple_size;
    if any(id.xy >= size) {
        return;
    }
    let r_mu_sun = multiple_r_mu_sun(id.xy, size);
    let r = r_mu_sun.x;
    let mu_sun = r_mu_sun.y;
    let sun = vec3<f32>(sqrt(max(1.0 - mu_sun * mu_sun, 0.0)), 0.0, mu_sun);
    var sums: array<vec3<f32>, MULTIPLE_TERMS>;
    var scattered = vec3<f32>(0.0);
    let side = MULTIPLE_DIRECTIONS_SIDE;
    for (var i = 0u; i < side * side; i++) {
        // Uniform over the sphere, each direction 4π / N steradians.
        let dir = grid_direction(i, side, 1.0, -1.0);
        let gathered = second_order(r, dir.z, mu_sun, dot(dir, sun));
        let basis = multiple_basis_of(dir);
        for (var j = 0u; j < MULTIPLE_TERMS; j++) {
            sums[j] += gathered.radiance * basis[j];
        }
        scattered += gathered.scattered;
    }
    let n = f32(side * side);
    // Each degree scattered on by the phases' moment, mixed by the share of Mie scattering here;
    // the constant term carries the higher orders' series.
    let medium = medium_at(r - bottom_km());
    let mie = vec3<f32>(medium.mie_scattering)
        / max(medium.rayleigh_scattering + vec3<f32>(medium.mie_scattering), vec3<f32>(1e-12));
    let moments = atmosphere.phase_moments;
    let k = array<vec3<f32>, 3>(
        vec3<f32>(1.0) / (vec3<f32>(1.0) - scattered / n),
        mie * moments.y,
        (vec3<f32>(1.0) - mie) * moments.x + mie * moments.z,
    );
    let degree = array<u32, MULTIPLE_TERMS>(0u, 1u, 1u, 2u, 2u, 2u);
    for (var j = 0u; j < MULTIPLE_TERMS; j++) {
        let term = sums[j] * (4.0 * PI / n) * multiple_basis_weight(j) * k[degree[j]];
        textureStore(multiple_out, id.xy + vec2<u32>(j * size.x, 0u), vec4<f32>(term, 1.0));
    }
}

@compute @workgroup_size(ATMOSPHERE_WORKGROUP, ATMOSPHERE_WORKGROUP)
fn sky_view_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = atmosphere.sky_view_size;
    if any(id.xy >= size) {
        return;
    }
    let r = atmosphere.radii.z;
    let mu_sun = atmosphere.radii.w;
    let angles = sky_view_angles(r, lut_unit(id.xy, size));
    let mu = cos(angles.x);
    let sin_zenith = sin(angles.x);
    // The sun in the view's vertical plane through x, the ray turned by the azimuth from it.
    let nu = sin_zenith * cos(angles.y) * sqrt(max(1.0 - mu_sun * mu_sun, 0.0)) + mu * mu_sun;
    textureStore(sky_view_out, id.xy, vec4<f32>(in_scattered(r, mu, mu_sun, nu), 1.0));
}

// The aerial-perspective volume (Hillaire's froxels): per tile of the screen (x, y) and slice z,
// the light the air scatters towards the camera and the share of light it lets through from the
// camera out to `aerial_distance(z)`, marched once per column, `AERIAL_SUBSTEPS` segments a slice.
@compute @workgroup_size(ATMOSPHERE_WORKGROUP, ATMOSPHERE_WORKGROUP)
fn aerial_perspective_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = atmosphere.aerial_size;
    if any(id.xy >= size) {
        return;
    }
    let ndc = vec2<f32>((f32(id.x) + 0.5) / f32(size.x) * 2.0 - 1.0, 1.0 - (f32(id.y) + 0.5) / f32(size.y) * 2.0);
    let near = atmosphere.view_world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    let dir = normalize(near.xyz / near.w);
    // From the camera itself, above the air or not (beyond the air the march gathers nothing).
    let r = atmosphere.up.w;
    let mu_sun = atmosphere.radii.w;
    let mu = clamp(dot(dir, atmosphere.up.xyz), -1.0, 1.0);
    let nu = dot(dir, atmosphere.sun_dir.xyz);
    let rayleigh = rayleigh_phase(nu);
    let mie = mie_phase(nu);
    var seen = vec3<f32>(1.0);
    var light = vec3<f32>(0.0);
    var t = 0.0;
    for (var z = 0u; z < atmosphere.aerial_slices; z++) {
        let end = aerial_distance(z);
        let dt = (end - t) / f32(AERIAL_SUBSTEPS);
        for (var k = 0u; k < AERIAL_SUBSTEPS; k++) {
            let s = ray_step_at(r, mu, mu_sun, nu, t + (f32(k) + 0.5) * dt, dt);
            light += seen * sky_source(s, nu, rayleigh, mie) * s.kept;
            seen *= s.through;
        }
        t = end;
        textureStore(aerial_inscatter_out, vec3<u32>(id.xy, z), vec4<f32>(light, 1.0));
        textureStore(aerial_transmittance_out, vec3<u32>(id.xy, z), vec4<f32>(seen, 1.0));
    }
}

// The sky's light on a level surface at each (altitude, sun's zenith cosine) of the table (the
// multiple-scattering table's parametrisation): the sky's radiance gathered from
// `IRRADIANCE_DIRECTIONS_SIDE`² directions of the upper hemisphere, even in azimuth and in the
// zenith cosine (so even in solid angle), each weighed by its cosine.
@compute @workgroup_size(ATMOSPHERE_WORKGROUP, ATMOSPHERE_WORKGROUP)
fn irradiance_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(irradiance_out);
    if any(id.xy >= size) {
        return;
    }
    let r_mu_sun = multiple_r_mu_sun(id.xy, size);
    let r = r_mu_sun.x;
    let mu_sun = r_mu_sun.y;
    let sun = vec3<f32>(sqrt(max(1.0 - mu_sun * mu_sun, 0.0)), 0.0, mu_sun);
    let side = IRRADIANCE_DIRECTIONS_SIDE;
    var gathered = vec3<f32>(0.0);
    for (var i = 0u; i < side * side; i++) {
        let dir = grid_direction(i, side, 0.0, 1.0);
        gathered += in_scattered(r, dir.z, mu_sun, dot(dir, sun)) * dir.z;
    }
    // Each direction weighs 2π / N steradians of the hemisphere.
    let n = f32(side * side);
    textureStore(irradiance_out, id.xy, vec4<f32>(gathered * 2.0 * PI / n, 1.0));
}

// The frame's balance for daylight: per channel, 1 over the light on level ground at sea level
// with the sun `DAYLIGHT_SUN_COS` from the zenith, sun and sky (a camera set to daylight: white
// ground under that sun is grey, 1, redder light at dusk is red; `display.wgsl` exposes it).
@compute @workgroup_size(1)
fn daylight_balance() {
    let r = bottom_km();
    let sun = sun_transmittance(r, DAYLIGHT_SUN_COS) * DAYLIGHT_SUN_COS;
    let sky = lut_read(irradiance, textureDimensions(irradiance), multiple_unit(r, DAYLIGHT_SUN_COS));
    daylight_out = vec4<f32>(1.0 / (sun + sky), 1.0);
}

struct SkyOut {
    @builtin(position) position: vec4<f32>,
    @location(0) ndc: vec2<f32>,
}

// One triangle over the screen at the far plane (reversed-Z: depth 0).
@vertex
fn vs_sky(@builtin(vertex_index) vertex: u32) -> SkyOut {
    let ndc = vec2<f32>(f32((vertex << 1u) & 2u) * 2.0 - 1.0, f32(vertex & 2u) * 2.0 - 1.0);
    return SkyOut(vec4<f32>(ndc, 0.0, 1.0), ndc);
}

// The sky from a view at radius `r` (km, it may lie above the air) along a ray at zenith cosine
// `mu`, marched through the air per pixel: from above the air, from where the ray enters it.
fn marched_sky(r: f32, mu: f32, mu_sun: f32, nu: f32) -> vec3<f32> {
    let top = top_km();
    if r <= top {
        return in_scattered(r, mu, mu_sun, nu);
    }
    let inside = r * r * (mu * mu - 1.0) + top * top;
    if mu >= 0.0 || inside < 0.0 {
        return vec3<f32>(0.0);
    }
    let entry = -r * mu - sqrt(inside);
    return in_scattered(top, (r * mu + entry) / top, clamp((r * mu_sun + entry * nu) / top, -1.0, 1.0), nu);
}

// What the sun's disk keeps along a ray from radius `r` at zenith cosine `mu`: the air's
// transmittance from where the ray is in it, nothing where the ground is in the way, all of it
// where the ray misses the air.
fn disk_transmittance(r: f32, mu: f32) -> vec3<f32> {
    let top = top_km();
    if r <= top {
        return sun_transmittance(r, mu);
    }
    let inside = r * r * (mu * mu - 1.0) + top * top;
    if mu >= 0.0 || inside < 0.0 {
        return vec3<f32>(1.0);
    }
    let entry = -r * mu - sqrt(inside);
    return sun_transmittance(top, (r * mu + entry) / top);
}

// The sun's disk along a camera-relative direction `dir` (unit) at zenith cosine `mu` from a view
// at radius `r_view`: the sun's irradiance spread over its solid angle, through the air, where
// the ground does not hide it.
fn sun_disk(dir: vec3<f32>, r_view: f32, mu: f32) -> vec3<f32> {
    let sun_radius = atmosphere.sun_dir.w;
    if dot(dir, atmosphere.sun_dir.xyz) > cos(sun_radius) && !hits_ground(r_view, mu) {
        return disk_transmittance(r_view, mu) / (PI * sun_radius * sun_radius);
    }
    return vec3<f32>(0.0);
}

// The view ray under a pixel of the full-screen triangle: the direction of the near plane's point,
// camera-relative.
fn sky_ray(ndc: vec2<f32>) -> vec3<f32> {
    let near = atmosphere.view_world_from_clip * vec4<f32>(ndc, 1.0, 1.0);
    return normalize(near.xyz / near.w);
}

// The sky from the sky-view table, for views in the lower air (up to `SKY_MARCHED_ABOVE_KM`).
@fragment
fn fs_sky(in: SkyOut) -> @location(0) vec4<f32> {
    let dir = sky_ray(in.ndc);
    let up = atmosphere.up.xyz;
    let sun = atmosphere.sun_dir.xyz;
    let mu = clamp(dot(dir, up), -1.0, 1.0);
    let across = dir - up * mu;
    let sun_across = sun - up * dot(sun, up);
    let lengths = length(across) * length(sun_across);
    var azimuth = 0.0;
    if lengths > 1e-6 {
        azimuth = acos(clamp(dot(across, sun_across) / lengths, -1.0, 1.0));
    }
    // One bilinear sample: texel centres span the unit square corner to corner, as `lut_read`.
    let size = vec2<f32>(atmosphere.sky_view_size);
    let unit = sky_view_unit(atmosphere.radii.z, acos(mu), azimuth);
    let uv = (clamp(unit, vec2<f32>(0.0), vec2<f32>(1.0)) * (size - 1.0) + 0.5) / size;
    let radiance = textureSampleLevel(sky_view, sky_sampler, uv, 0.0).rgb + sun_disk(dir, atmosphere.up.w, mu);
    return vec4<f32>(balanced(radiance * PI), 1.0);
}

// The sky marched per pixel, for views above `SKY_MARCHED_ABOVE_KM`, where the table's rows about
// the horizon grow coarser than the limb they hold. Its own pipeline: on lavapipe a fragment
// shader that merely holds the march's loops grows the process's memory every frame, so the
// table's pipeline must not (docs/atmosphere.md).
@fragment
fn fs_sky_marched(in: SkyOut) -> @location(0) vec4<f32> {
    let dir = sky_ray(in.ndc);
    let up = atmosphere.up.xyz;
    let sun = atmosphere.sun_dir.xyz;
    let r_view = atmosphere.up.w;
    let mu = clamp(dot(dir, up), -1.0, 1.0);
    let radiance = marched_sky(r_view, mu, clamp(dot(sun, up), -1.0, 1.0), dot(dir, sun)) + sun_disk(dir, r_view, mu);
    return vec4<f32>(balanced(radiance * PI), 1.0);
}
