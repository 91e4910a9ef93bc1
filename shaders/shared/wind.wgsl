// The wind of the Virtual Forest (Rust: `seeds::wind`, which says how it works and bounds how far
// it moves anything): every representation of a seed bends by this one field, so a cross-fade
// shows one plant swaying. `wind`: downwind unit vector (xy), a top's mean lean and sway per metre
// of height (zw); `wave`: wind time in seconds (x), the gusts' wavenumber per metre (y) and their
// phase at the camera (z).

// Where the top of a seed `height_m` tall, anchored at `anchor_rel_m` (camera-relative), has moved,
// metres (xy): its lean along the wind, weakened between the gusts travelling downwind, and its own
// elliptical sway, phased by its jitter's hash.
fn wind_top_m(wind: vec4<f32>, wave: vec4<f32>, anchor_rel_m: vec3<f32>, height_m: f32, jitter: u32) -> vec2<f32> {
    let tau = 6.2831853;
    let gust = 0.5 + 0.5 * sin(dot(anchor_rel_m.xy, wind.xy) * wave.y + wave.z);
    let lean = wind.z * (1.0 - WIND_GUST_DEPTH * (1.0 - gust));
    let hz = WIND_SWAY_HZ_AT_1M * inverseSqrt(max(height_m, 1.0));
    let phases = pcg(jitter);
    // Whole turns first (fract), so long flights keep the sines' precision.
    let turn_along = fract(hz * wave.x + f32(phases & 0xffffu) / 65536.0);
    let turn_across = fract(hz * WIND_CROSS_HZ_RATIO * wave.x + f32(phases >> 16u) / 65536.0);
    let along = lean + wind.w * sin(tau * turn_along);
    let across = WIND_CROSS_OF_SWAY * wind.w * sin(tau * turn_across);
    return (wind.xy * along + vec2<f32>(-wind.y, wind.x) * across) * height_m;
}

// A leaf's vertex `leaf_m` from its pivot (world axes, metres; zero for rigid parts) turned about
// the pivot: the leaf flaps about the horizontal axis across the wind, at its own phase and
// frequency (hashed from the pivot, which all its vertices share), by an angle growing with the
// lean; the move is capped at WIND_FLUTTER_MAX_PER_HEIGHT of the plant's height.
fn wind_flutter(wind: vec4<f32>, wave: vec4<f32>, leaf_m: vec3<f32>, pivot_model_m: vec3<f32>, height_m: f32) -> vec3<f32> {
    let tau = 6.2831853;
    let p = bitcast<vec3<u32>>(pivot_model_m);
    let key = pcg(p.x ^ pcg(p.y ^ pcg(p.z)));
    let hz = WIND_FLUTTER_HZ * (1.0 + 0.5 * f32(key >> 16u) / 65536.0);
    let turn = fract(hz * wave.x + f32(key & 0xffffu) / 65536.0);
    let angle = min(WIND_FLUTTER_RAD_PER_LEAN * wind.z, WIND_FLUTTER_MAX_RAD) * sin(tau * turn);
    // Rodrigues' rotation about the unit axis k.
    let k = vec3<f32>(-wind.y, wind.x, 0.0);
    let turned = leaf_m * cos(angle) + cross(k, leaf_m) * sin(angle) + k * (dot(k, leaf_m) * (1.0 - cos(angle)));
    let moved = turned - leaf_m;
    let cap_m = WIND_FLUTTER_MAX_PER_HEIGHT * height_m;
    let moved_m = length(moved);
    if moved_m > cap_m {
        return leaf_m + moved * (cap_m / moved_m);
    }
    return turned;
}

// A point `offset_m` from the base of a seed `height_m` tall (world axes, metres), bent so that its
// top moves by `top_m`: horizontally by top_m · h² (h its height fraction, clamped to [0, 1]), and
// down by the bend's arc to second order, so the plant does not stretch.
fn wind_bend(offset_m: vec3<f32>, top_m: vec2<f32>, height_m: f32) -> vec3<f32> {
    let h = clamp(offset_m.z / height_m, 0.0, 1.0);
    let moved = top_m * (h * h);
    let drop = dot(moved, moved) / (2.0 * max(length(offset_m), 1e-3));
    return offset_m + vec3<f32>(moved, -drop);
}
