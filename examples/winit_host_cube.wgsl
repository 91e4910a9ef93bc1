// The host's cubes (examples/winit_host.rs): 36 vertices a cube, made from its camera-relative
// centre and half size; magenta, each face a shade of it.

struct Cubes {
    clip_from_rel: mat4x4<f32>,
    // xyz: the centre relative to the camera, metres; w: half the side.
    cubes: array<vec4<f32>>,
}

@group(0) @binding(0) var<storage, read> scene: Cubes;

struct Vertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) shade: f32,
}

@vertex
fn vs(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> Vertex {
    let face = v / 6u;
    // The face's two triangles over its corners (u, w) in {-1, 1}².
    let corners = array<vec2<f32>, 6>(vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0),
                                      vec2(-1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0));
    let c = corners[v % 6u];
    let axis = face % 3u;
    let side = select(-1.0, 1.0, face >= 3u);
    var p: vec3<f32>;
    if axis == 0u {
        p = vec3(side, c.x, c.y);
    } else if axis == 1u {
        p = vec3(c.x, side, c.y);
    } else {
        p = vec3(c.x, c.y, side);
    }
    let cube = scene.cubes[i];
    var out: Vertex;
    out.clip = scene.clip_from_rel * vec4<f32>(cube.xyz + cube.w * p, 1.0);
    out.shade = 0.6 + 0.08 * f32(face);
    return out;
}

@fragment
fn fs(in: Vertex) -> @location(0) vec4<f32> {
    return vec4<f32>(in.shade, 0.0, in.shade, 1.0);
}
