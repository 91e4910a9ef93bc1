// Cloud shadows (Rust: `light`, which says how it works; twin `CloudShadowFrame::sun_visible`).
// `field`: where the camera's sun ray meets the cloud layer, in cells of the largest octave modulo
// the period (xy), cells per metre (z), the noise threshold of a cloud's edge (w); `shift`: cells
// the meeting point moves per metre of height (xy), the share of sunlight a cloud's core holds
// back (z, 0: no clouds), the Earth's fall per square metre from the camera (w, 0 flat).

// The value of lattice point `i` of octave `octave`, 0 to 1, repeating every period.
fn cloud_lattice(i: vec2<i32>, octave: u32) -> f32 {
    let mask = i32(CLOUD_PERIOD_CELLS << octave) - 1;
    let m = vec2<u32>(i & vec2<i32>(mask));
    return f32(pcg(m.x ^ pcg(m.y ^ pcg(octave ^ CLOUD_SALT))) >> 8u) / 16777216.0;
}

// Octave `octave`'s value noise at `q` (its own cells).
fn cloud_value(q: vec2<f32>, octave: u32) -> f32 {
    let cell = floor(q);
    let f = q - cell;
    let w = f * f * (3.0 - 2.0 * f);
    let i = vec2<i32>(cell);
    let south = mix(cloud_lattice(i, octave), cloud_lattice(i + vec2<i32>(1, 0), octave), w.x);
    let north = mix(cloud_lattice(i + vec2<i32>(0, 1), octave), cloud_lattice(i + vec2<i32>(1, 1), octave), w.x);
    return mix(south, north, w.y);
}

// The clouds' density at `q` (cells of the largest octave), 0 to 1.
fn cloud_density(q: vec2<f32>) -> f32 {
    var sum = 0.0;
    var weight = 0.5;
    var total = 0.0;
    var p = q;
    for (var octave = 0u; octave < CLOUD_OCTAVES; octave++) {
        sum += weight * cloud_value(p, octave);
        total += weight;
        p *= 2.0;
        weight *= 0.5;
    }
    return sum / total;
}

// The share of the sun's light that reaches the point `rel_m` from the camera: 1 without clouds
// (returned before any arithmetic, so a cloudless frame is bit for bit one without this code).
fn sun_through_clouds(field: vec4<f32>, shift: vec4<f32>, rel_m: vec3<f32>) -> f32 {
    if shift.z <= 0.0 {
        return 1.0;
    }
    // Its height over the layer's shell: the camera frame's, plus the Earth's fall (0 flat).
    let up_m = rel_m.z + shift.w * (rel_m.x * rel_m.x + rel_m.y * rel_m.y);
    let q = field.xy + rel_m.xy * field.z + up_m * shift.xy;
    return 1.0 - shift.z * smoothstep(field.w - CLOUD_EDGE, field.w + CLOUD_EDGE, cloud_density(q));
}
