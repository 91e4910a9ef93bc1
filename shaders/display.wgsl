// The display pass: the frame's light, balanced for daylight (1 is white ground in daylight), as
// the screen shows it. Exposed to a physical scale (`passes::display`): its luminance in cd/m²
// (`luminance(1 / daylight)` is daylight's own, in units of the sun's irradiance, which
// `exposure.x` takes to cd/m² and exposes at EV100), then through the tone curve `TONE_CURVE`
// picks, a matrix, a curve per channel, a matrix back. The target is sRGB: the hardware encodes
// on store. Over a host's linear HDR target the exposed light is written instead, for the host's
// own tone curve. Twin: `reference::display`.

struct DisplayUniforms {
    into_curve: array<vec4<f32>, 3>,
    out_of_curve: array<vec4<f32>, 3>,
    coefficients: array<vec4<f32>, 2>,
    encoding: vec4<f32>,
    luminance: vec4<f32>,
    exposure: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> display: DisplayUniforms;
@group(0) @binding(1) var<uniform> daylight: vec4<f32>;
@group(0) @binding(2) var scene: texture_2d<f32>;

// The curve this pipeline shows through (`ToneCurve::index`), and the indices of AgX and of the
// linear display, all set by `DisplayPass::new`: a pipeline per curve, so none holds another's
// code.
override TONE_CURVE: u32;
override AGX: u32;
override LINEAR: u32;

@vertex
fn vs_display(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    let ndc = vec2<f32>(f32((vertex << 1u) & 2u) * 2.0 - 1.0, f32(vertex & 2u) * 2.0 - 1.0);
    return vec4<f32>(ndc, 0.0, 1.0);
}

fn by_rows(rows: array<vec4<f32>, 3>, v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(rows[0].xyz, v), dot(rows[1].xyz, v), dot(rows[2].xyz, v));
}

// AgX's sigmoid of log-encoded light, display-encoded: a polynomial, lowest power first.
fn agx(x: vec3<f32>) -> vec3<f32> {
    let c = display.coefficients;
    let span = display.encoding.y - display.encoding.x;
    let u = (clamp(log2(max(x, vec3<f32>(1e-10))), vec3<f32>(display.encoding.x), vec3<f32>(display.encoding.y)) - display.encoding.x) / span;
    let powers = array<f32, 7>(c[0].x, c[0].y, c[0].z, c[0].w, c[1].x, c[1].y, c[1].z);
    var y = vec3<f32>(powers[6]);
    for (var k = 5; k >= 0; k--) {
        y = y * u + powers[k];
    }
    return y;
}

// Hill's rational fit of ACES's reference rendering and sRGB output: linear in, linear out.
fn aces(x: vec3<f32>) -> vec3<f32> {
    let c = display.coefficients[0];
    let e = display.coefficients[1].x;
    return (x * (x + c.x) - c.y) / (x * (c.z * x + c.w) + e);
}

// The balanced light `balanced` exposed: scene-referred linear light (sRGB primaries) that a tone
// curve takes, 0.18 mid grey at the exposure.
fn exposed(balanced: vec3<f32>) -> vec3<f32> {
    let daylight_luminance = dot(display.luminance.xyz, 1.0 / daylight.xyz);
    return max(balanced, vec3<f32>(0.0)) * (daylight_luminance * display.exposure.x);
}

// The displayed linear light of the balanced light `balanced`.
fn shown(balanced: vec3<f32>) -> vec3<f32> {
    if TONE_CURVE == LINEAR {
        return clamp(balanced, vec3<f32>(0.0), vec3<f32>(1.0));
    }
    let into = by_rows(display.into_curve, exposed(balanced));
    if TONE_CURVE == AGX {
        let encoded = by_rows(display.out_of_curve, agx(into));
        return pow(clamp(encoded, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(display.encoding.z));
    }
    return clamp(by_rows(display.out_of_curve, aces(into)), vec3<f32>(0.0), vec3<f32>(1.0));
}

@fragment
fn fs_display(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let balanced = textureLoad(scene, vec2<i32>(at.xy), 0).rgb;
    return vec4<f32>(shown(min(balanced, vec3<f32>(SCENE_LIGHT_MAX))), 1.0);
}

// Over the host's colour (`Renderer::render_into`): the light's alpha is how much of the pixel
// terramp drew (its light premultiplied by it), so the light shown is the light over the alpha,
// blended over what the host drew by that alpha. This is that light, balanced, and the alpha (0
// where terramp drew nothing: the host's pixel stays).
fn covering(at: vec4<f32>) -> vec4<f32> {
    let light = textureLoad(scene, vec2<i32>(at.xy), 0);
    if light.a <= 0.0 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(min(light.rgb / light.a, vec3<f32>(SCENE_LIGHT_MAX)), light.a);
}

// Over a display-ready (sRGB) host colour: the light shown.
@fragment
fn fs_display_over(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let light = covering(at);
    return vec4<f32>(shown(light.rgb), light.a);
}

// Over a host's linear HDR colour (a float target the host tone-maps itself): the light exposed,
// through no curve.
@fragment
fn fs_display_over_linear(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let light = covering(at);
    return vec4<f32>(min(exposed(light.rgb), vec3<f32>(HOST_HDR_MAX)), light.a);
}
