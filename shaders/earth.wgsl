// The Earth mapping's probes (`earth::gpu`): each point placed by `earth_position_m`
// (`shared/earth.wgsl`) on its node, for the test that holds the shader to its Rust twin
// (`earth::local::NodeMapping::position_m`); and each point, as a vector, stood by `earth_stand`
// on its node's vertical (`d_h`).

struct EarthProbePoint {
    offset_m: vec3<f32>,
    node: u32,
}

@group(0) @binding(0) var<storage, read> probe_nodes: array<EarthNode>;
@group(0) @binding(1) var<storage, read> probe_points: array<EarthProbePoint>;
@group(0) @binding(2) var<storage, read_write> probe_positions: array<vec4<f32>>;

@compute @workgroup_size(EARTH_PROBE_WORKGROUP)
fn probe_earth_positions(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&probe_points) {
        return;
    }
    let point = probe_points[i];
    probe_positions[i] = vec4<f32>(earth_position_m(probe_nodes[point.node], point.offset_m), 0.0);
}

@compute @workgroup_size(EARTH_PROBE_WORKGROUP)
fn probe_earth_stand(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&probe_points) {
        return;
    }
    let point = probe_points[i];
    probe_positions[i] = vec4<f32>(earth_stand(point.offset_m, probe_nodes[point.node].d_h.xyz), 0.0);
}
