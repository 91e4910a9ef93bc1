// The air for the passes that light what they draw (the ground, the seeds, the texcells): the
// light that reaches a point (`light_at`: the sun through the air, none where the Earth hides
// it, and the sky's light on a level surface there, from the atmosphere pass's tables) and the
// air between it and the camera (`through_air`: the aerial-perspective volume's in-scattering
// and transmittance at the fragment's tile and distance), balanced for daylight (`balanced`). The
// atmosphere pass makes every table this reads; its bind group is `passes::atmosphere::gpu::air`.
// Twin: `reference::atmosphere::light`.

// Storage, not uniform: lavapipe specialises shaders on uniforms that steer branches, and these
// change every frame (`DrawSeedsUniforms` says more).
@group(2) @binding(10) var<storage, read> atmosphere: AtmosphereUniforms;
@group(2) @binding(11) var<uniform> daylight: vec4<f32>;
@group(2) @binding(12) var transmittance: texture_2d<f32>;
@group(2) @binding(13) var irradiance: texture_2d<f32>;
@group(2) @binding(14) var aerial_inscatter: texture_3d<f32>;
@group(2) @binding(15) var aerial_transmittance: texture_3d<f32>;
@group(2) @binding(16) var aerial_sampler: sampler;
@group(2) @binding(17) var multiple: texture_2d<f32>;

// Whether this pipeline marches the air per pixel (views above `SKY_MARCHED_ABOVE_KM`) or reads
// the volume: a pipeline constant, so each variant holds only its own code (on lavapipe a march
// in a branch a view never takes still costs the volume's pipeline a third of its time).
override AIR_MARCHED: bool = false;

// The light at a point, per unit of the sun's irradiance above the air: the sun's share that
// reaches it, the sky's light on a level surface there, and the point's zenith.
struct SunAndSky {
    sun: vec3<f32>,
    sky: vec3<f32>,
    up: vec3<f32>,
}

// The light at `rel_m` from the camera (metres, the frame's camera-relative world). The air is a
// sphere whose centre lies below the camera along its zenith, so a point far off sees the sun
// lower, as on the Earth; on a flat dataset the ground is flat but the air is not.
fn light_at(rel_m: vec3<f32>) -> SunAndSky {
    let from_centre_km = rel_m * 0.001 + atmosphere.up.xyz * atmosphere.up.w;
    let length_km = length(from_centre_km);
    let up = from_centre_km / length_km;
    let r = clamp(length_km, bottom_km(), top_km());
    let mu_sun = clamp(dot(up, atmosphere.sun_dir.xyz), -1.0, 1.0);
    let sky = lut_read(irradiance, textureDimensions(irradiance), multiple_unit(r, mu_sun));
    return SunAndSky(sun_transmittance(r, mu_sun), sky, up);
}

// What the air adds and keeps between the camera and a point at `rel_m` from it: the volume's
// tile where the point lies on the screen, its slices (the distance's square root) filtered
// linearly, and nearer than the first slice's reach a blend towards no air at all.
struct AirBetween {
    in_scattered: vec3<f32>,
    transmittance: vec3<f32>,
}

fn air_between(rel_m: vec3<f32>) -> AirBetween {
    let clip = atmosphere.clip_from_view_world * vec4<f32>(rel_m, 1.0);
    let ndc = clip.xy / max(clip.w, 1e-6);
    let distance_km = length(rel_m) * 0.001;
    let slices = f32(atmosphere.aerial_slices);
    let slice = sqrt(distance_km / atmosphere.aerial_far_km) * slices - 1.0;
    let at = vec3<f32>(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y, (clamp(slice, 0.0, slices - 1.0) + 0.5) / slices);
    let in_scattered = textureSampleLevel(aerial_inscatter, aerial_sampler, at, 0.0).rgb;
    let kept = textureSampleLevel(aerial_transmittance, aerial_sampler, at, 0.0).rgb;
    let near = clamp(distance_km / aerial_distance(0u), 0.0, 1.0);
    return AirBetween(in_scattered * near, mix(vec3<f32>(1.0), kept, near));
}

// The same marched per pixel, for views above `SKY_MARCHED_ABOVE_KM` (as the sky is; the
// pipelines made with `AIR_MARCHED`): from
// there the volume's slices, square-spaced from the camera, would hold a ray's whole air in one
// or two of them. `SKY_VIEW_STEPS` segments from the point back towards the camera, square-spaced
// so the dense air at the point's end is finely sampled, composited back to front, up to where
// the ray entered the air.
fn air_marched(rel_m: vec3<f32>) -> AirBetween {
    let r = atmosphere.up.w;
    let distance_km = length(rel_m) * 0.001;
    let dir = rel_m * (0.001 / max(distance_km, 1e-9));
    let mu = dot(dir, atmosphere.up.xyz);
    let nu = dot(dir, atmosphere.sun_dir.xyz);
    let top = top_km();
    var entry = 0.0;
    if r > top {
        let inside = r * r * (mu * mu - 1.0) + top * top;
        if mu >= 0.0 || inside < 0.0 {
            return AirBetween(vec3<f32>(0.0), vec3<f32>(1.0));
        }
        entry = -r * mu - sqrt(inside);
    }
    let length = max(distance_km - entry, 0.0);
    let rayleigh = rayleigh_phase(nu);
    let mie = mie_phase(nu);
    var light = vec3<f32>(0.0);
    var seen = vec3<f32>(1.0);
    for (var k = 0u; k < SKY_VIEW_STEPS; k++) {
        let segment = ray_segment(k, SKY_VIEW_STEPS, length);
        let s = ray_step_at(r, mu, atmosphere.radii.w, nu, distance_km - segment.x, segment.y);
        light = sky_source(s, nu, rayleigh, mie) * s.kept + s.through * light;
        seen *= s.through;
    }
    return AirBetween(light, seen);
}

// A point's light as the frame holds it: `lit_pi` (its radiance times π: albedo times the light that
// falls on it) at `rel_m` from the camera, through the air between, unless aerial perspective
// is off.
fn through_air(lit_pi: vec3<f32>, rel_m: vec3<f32>) -> vec3<f32> {
    if atmosphere.aerial_on == 0u {
        return balanced(lit_pi);
    }
    var air: AirBetween;
    if AIR_MARCHED {
        air = air_marched(rel_m);
    } else {
        air = air_between(rel_m);
    }
    return balanced(lit_pi * air.transmittance + PI * air.in_scattered);
}

// The light on level ground (its zenith `light.up`) of the sun along `sun` through clouds that
// keep `clouds` of it: the colour follow-up's yardstick, which the photograph was lit by.
fn level_ground_light(light: SunAndSky, sun: vec3<f32>, clouds: f32) -> vec3<f32> {
    return light.sun * max(dot(light.up, sun), 0.0) * clouds + light.sky;
}
